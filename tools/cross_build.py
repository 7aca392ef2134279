#!/usr/bin/env python3
"""The Windows and macOS `_radiosity` modules, cross-built here with zig: one per
CPython of tools/cpython.py's VERSIONS, written to BUILD/cross/PLATFORM/modules
(`make package` and `make test-platforms` run it; incremental).

For each platform: its Embree and oneTBB (tools/cross_deps.py), a folder of links
to the headers the module is built against (pybind11 and GLM as for Linux, and
each CPython's headers from the org.bytedeco:cpython jar of that platform,
tools/cpython.py; Windows also its import library python3XY.lib), then
native/portable configured with the platform's zig toolchain
(native/portable/platform.cmake says what differs). macOS modules are then
signed ad hoc with rcodesign (tools/rcodesign.py), as arm64 Macs require.
Last, the solver's C++ unit tests for the platform (native/portable/unit_tests.cmake),
in BUILD/cross/PLATFORM/build-module/unit-tests.

JavaCPP publishes macosx-arm64 jars of CPython 3.13 only: the arm64 modules of
3.10 and 3.11 are built against the macosx-x86_64 headers of that version.
CPython's macOS headers are the same for both architectures (python.org's
universal2 builds ship one pyconfig.h for both), so nothing of the ABI differs.

    python3 tools/cross_build.py --build build windows-x64 macos-arm64 macos-x64
    python3 tools/cross_build.py --build build --if-deps    # those whose dependencies are made
"""

import argparse
import os
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import cpython        # tools/cpython.py: the CPython jars
import cross_deps     # tools/cross_deps.py: the toolchains, Embree and oneTBB
import portable_deps  # tools/portable_deps.py: pybind11 and GLM, as the Linux build has them
import rcodesign      # tools/rcodesign.py: ad hoc signatures for macOS

ROOT = Path(__file__).resolve().parent.parent
PLATFORMS = list(cross_deps.PLATFORMS)
CLASSIFIERS = {"windows-x64": "windows-x86_64", "macos-arm64": "macosx-arm64", "macos-x64": "macosx-x86_64"}


def classifier(platform, minor):
    """The jar whose headers a module for `platform` and Python `minor` is built against."""
    wanted = CLASSIFIERS[platform]
    if (cpython.VERSIONS[minor], wanted) in cpython.SHA256:
        return wanted
    if platform == "macos-arm64":
        return "macosx-x86_64"   # the same headers (see above)
    raise cpython.CPythonError("no CPython %s headers for %s" % (minor, platform))


def suffix(platform, minor):
    """The file name ending CPython `minor` of `platform` imports an extension module by."""
    tag = minor.replace(".", "")
    return ".cp%s-win_amd64.pyd" % tag if platform == "windows-x64" else ".cpython-%s-darwin.so" % tag


def link(path, target):
    if path.is_symlink() and os.readlink(path) == str(target):
        return
    path.parent.mkdir(parents=True, exist_ok=True)
    if path.is_symlink() or path.exists():
        path.unlink()
    path.symlink_to(target)


def headers(build, platform, folder):
    """FOLDER/headers (pybind11, glm, python3.X) and, for Windows, FOLDER/libs/python3XY.lib."""
    shared = cross_deps.portable_deps_folder(build)
    link(folder / "headers" / "pybind11", portable_deps.pybind11(shared))
    link(folder / "headers" / "glm", Path(portable_deps.HEADERS["glm"]))
    for minor in cpython.VERSIONS:
        jar = classifier(platform, minor)
        link(folder / "headers" / ("python" + minor), cpython.include_dir(build, minor, jar))
        if platform == "windows-x64":
            link(folder / "libs" / ("python%s.lib" % minor.replace(".", "")),
                 cpython.import_library(build, minor, jar))


def version():
    return tomllib.loads((ROOT / "addon" / "blender_manifest.toml").read_text())["version"]


def modules_dir(build, platform):
    return cross_deps.folder_of(build, platform) / "modules"


def modules(build, platform):
    """{Python minor: module path} of the modules built for `platform` (missing ones left out)."""
    found = {}
    for minor in cpython.VERSIONS:
        path = modules_dir(build, platform) / ("_radiosity" + suffix(platform, minor))
        if path.exists():
            found[minor] = path
    return found


def build_modules(build, platform, jobs):
    """Build (or bring up to date) the modules of `platform`; returns modules()."""
    folder = cross_deps.build(build, platform)
    headers(build, platform, folder)
    work = folder / "build-module"
    start = time.perf_counter()
    if not (work / "CMakeCache.txt").exists():
        cross_deps.log("%s: configuring native/portable" % platform)
        portable_deps.run(["cmake", "-S", str(ROOT / "native" / "portable"), "-B", str(work),
                           "-DCMAKE_TOOLCHAIN_FILE=%s" % (folder / "zig.cmake"), "-DCMAKE_BUILD_TYPE=Release",
                           "-DRADIOSITY_DEPS=%s" % folder, "-DRADIOSITY_OUTPUT_DIR=%s" % modules_dir(build, platform),
                           "-DRADIOSITY_VERSION=%s" % version(), "-DRADIOSITY_UNIT_TESTS=ON"], folder / "module-configure.log")
    modules_targets = ["_radiosity_cp%s" % m.replace(".", "") for m in cpython.VERSIONS]
    portable_deps.run(["cmake", "--build", str(work), "-j", str(jobs), "--target", *modules_targets],
                      folder / "module-build.log")
    found = modules(build, platform)
    if platform.startswith("macos"):
        for path in found.values():
            rcodesign.sign(build, path)
    missing = [m for m in cpython.VERSIONS if m not in found]
    if missing:
        sys.exit("error: no %s module for Python %s; see %s" % (platform, ", ".join(missing),
                                                                folder / "module-build.log"))
    cross_deps.log("%s: %s (%.0f s)" % (platform, ", ".join(
        "%s %.1f MB" % (p.name, p.stat().st_size / 1e6) for p in found.values()), time.perf_counter() - start))
    # Then the C++ unit tests for the platform (run under Wine for Windows, linked for macOS).
    start = time.perf_counter()
    portable_deps.run(["cmake", "--build", str(work), "-j", str(jobs), "--target", "radiosity_tests"],
                      folder / "unit-tests-build.log")
    cross_deps.log("%s: %s (%.0f s)" % (platform, unit_tests(build, platform), time.perf_counter() - start))
    return found


def unit_tests(build, platform):
    """The C++ unit tests' program built for `platform`."""
    name = "radiosity_tests.exe" if platform == "windows-x64" else "radiosity_tests"
    return cross_deps.folder_of(build, platform) / "build-module" / "unit-tests" / name


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    parser.add_argument("--if-deps", action="store_true",
                        help="only the platforms whose Embree and oneTBB are built (make package)")
    # Checked here, not with `choices`: Debian's Python 3.11 checks an empty
    # list of them as one value and refuses it (`make package` failed on a
    # fresh clone).
    parser.add_argument("platforms", nargs="*", help="of %s; all when none is named" % ", ".join(PLATFORMS))
    args = parser.parse_args()
    unknown = sorted(set(args.platforms) - set(PLATFORMS))
    if unknown:
        parser.error("unknown platform %s (choose from %s)" % (", ".join(unknown), ", ".join(PLATFORMS)))
    for platform in args.platforms or PLATFORMS:
        folder = cross_deps.folder_of(args.build, platform)
        if args.if_deps and not ((folder / "onetbb.done").exists() and (folder / "embree.done").exists()):
            continue
        build_modules(args.build, platform, args.jobs)
    return 0


if __name__ == "__main__":
    sys.exit(main())
