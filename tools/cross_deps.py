#!/usr/bin/env python3
"""What the Windows and macOS modules' builds need, made once per platform under
BUILD/cross/PLATFORM; a no-op once there (`make package` and `make test-platforms`
run it through tools/cross_build.py).

The Linux build's recipe (tools/portable_deps.py) for other targets of the same zig:
- wrappers and a CMake toolchain file for zig's clang targeting the platform
  (Windows: x86_64-windows-gnu, MinGW-w64 headers over the Universal CRT with
  LLVM's libc++ linked in; macOS: aarch64-macos.11.0 or x86_64-macos.11.0, the
  Mach-O linker against zig's libSystem stubs, libc++ linked in);
- Embree and oneTBB from the same pinned Debian sources, built static for it.
  Embree as on Linux (triangles, filter functions, single rays, its own tasking),
  with one ISA: SSE2 on x86-64, NEON (Embree's ARM path, sse2neon) on arm64.

    python3 tools/cross_deps.py --build build windows-x64 [macos-arm64 macos-x64]
"""

import argparse
import shutil
import sys
import time
from pathlib import Path

import portable_deps  # tools/portable_deps.py: zig, the Debian sources, the static builds

# platform (Blender's name) -> zig's target and CMake's system name and processor
PLATFORMS = {
    "windows-x64": {"zig": "x86_64-windows-gnu", "system": "Windows", "processor": "AMD64"},
    "macos-arm64": {"zig": "aarch64-macos.11.0", "system": "Darwin", "processor": "arm64"},
    "macos-x64": {"zig": "x86_64-macos.11.0", "system": "Darwin", "processor": "x86_64"},
}
# The Linux build's Embree options, but one ISA a target has: NEON on arm64 (its
# double-pumped NEON2X, Embree's default on Apple, doubles the kernels built).
ARM_ISA = ["-DEMBREE_ISA_NEON=ON", "-DEMBREE_ISA_NEON2X=OFF"]
# MinGW's math.h declares M_PI, which Embree uses, only when asked to.
WINDOWS_EMBREE = ["-DEMBREE_IGNORE_CMAKE_CXX_FLAGS=OFF", "-DCMAKE_CXX_FLAGS=-D_USE_MATH_DEFINES"]
# Embree asks Windows for the privilege of large pages (ADVAPI32's token functions)
# when it starts; the solver never uses large pages, and the module is to need no
# DLL beyond KERNEL32 and the C runtime: on Windows it does not ask (Windows-only code).
EMBREE_WINDOWS_FIXES = {
    "common/sys/alloc.cpp": ("  bool win_enable_selockmemoryprivilege (bool verbose)\n  {\n    HANDLE hToken;",
                             "  bool win_enable_selockmemoryprivilege (bool verbose)\n  {\n"
                             "    return false;   // tools/cross_deps.py: no large pages, no ADVAPI32\n  }\n"
                             "  static bool win_enable_selockmemoryprivilege_unused (bool verbose)\n  {\n"
                             "    HANDLE hToken;"),
}
# Embree marks its task scheduler's functions visibility("default") on every system
# but Windows, static library or not; zig's Mach-O linker takes no export list, so
# the macOS modules would export them: like its Windows static build, none.
EMBREE_STATIC_VISIBILITY_FIXES = {
    "common/sys/platform.h": ('#else\n#  define dll_export __attribute__ ((visibility ("default")))\n',
                              '#elif defined(EMBREE_STATIC_LIB)   // tools/cross_deps.py: nothing exported\n'
                              '#  define dll_export\n#  define dll_import\n'
                              '#else\n#  define dll_export __attribute__ ((visibility ("default")))\n'),
}
# macOS: oneTBB compiled with hidden symbols (it hides them with an export list,
# which a static library never gets), for the same reason. Its CMakeLists asks for
# CMake 3.1, whose policies apply a visibility preset to shared libraries only
# (CMP0063): without the policy set the archive's functions stayed visible and the
# first arm64 modules exported 227 of oneTBB's (llvm-nm-16).
DARWIN_TBB = ["-DCMAKE_CXX_VISIBILITY_PRESET=hidden", "-DCMAKE_VISIBILITY_INLINES_HIDDEN=ON",
              "-DCMAKE_POLICY_DEFAULT_CMP0063=NEW"]
# oneTBB marks its functions __declspec(dllexport) under MinGW, also in a static
# library, which would export them from the module: its export header is
# pre-empted (guard and macros defined empty) for the Windows build.
TBB_STATIC_EXPORTS = """// oneTBB's detail/_export.h for a static MinGW build (tools/cross_deps.py): nothing exported.
#define __TBB_detail__export_H
#define TBB_EXPORT
#define TBBMALLOC_EXPORT
#define TBBBIND_EXPORT
"""
# Windows: oneTBB's and Embree's version resources (tbb.rc, embree.rc) are compiled by zig's resource
# compiler; nothing links it, as nothing references it in the static library.
RC_WRAPPER = """#!/usr/bin/env python3
# windres's command line (as CMake gives it for MinGW) to `zig rc` (tools/cross_deps.py).
import os, sys
args, out, defines = sys.argv[1:], None, []
source = None
i = 0
while i < len(args):
    a = args[i]
    if a in ("-O", "--output-format"):
        i += 1
    elif a.startswith("-D") or a.startswith("-I"):
        defines.append(("/d" if a[1] == "D" else "/i") + (a[2:] or args[i + 1]))
        i += 0 if a[2:] else 1
    elif a in ("-o",):
        out = args[i + 1]; i += 1
    elif a.startswith("-"):
        pass
    elif source is None:
        source = a
    else:
        out = a
    i += 1
if open(source, "rb").read(2) == b"\\xff\\xfe":   # UTF-16 (embree.rc), which zig rc rejects: as UTF-8
    text = open(source, encoding="utf-16").read()
    defines.append("/i" + os.path.dirname(os.path.abspath(source)))
    source = out + ".utf8.rc"
    open(source, "w", encoding="utf-8").write(text)
os.environ["ZIG_GLOBAL_CACHE_DIR"] = %(cache)r
os.execv(%(python)r, [%(python)r, "-m", "ziglang", "rc", "/:output-format", "coff", "/:target", "x64",
                      *defines, "/fo", out, source])
"""


def log(message):
    print("[cross] " + message, flush=True)


def folder_of(build, platform):
    return Path(build).resolve() / "cross" / platform


def cache_of(build):
    """One zig cache for every cross target (its libc++ and C runtimes, per target)."""
    return Path(build).resolve() / "cross" / "zig-cache"


def toolchain(build, platform):
    """Wrappers and zig.cmake for `platform` in its folder."""
    spec, folder = PLATFORMS[platform], folder_of(build, platform)
    python = portable_deps_folder(build) / "zig-env" / "bin" / "python"
    cache = cache_of(build)
    bin_dir = folder / "bin"
    bin_dir.mkdir(parents=True, exist_ok=True)
    for name, command in (("zcc", "cc -target " + spec["zig"]), ("zc++", "c++ -target " + spec["zig"]),
                          ("zar", "ar"), ("zranlib", "ranlib")):
        path = bin_dir / name
        path.write_text('#!/bin/sh\nZIG_GLOBAL_CACHE_DIR="%s" exec "%s" -m ziglang %s "$@"\n'
                        % (cache, python, command))
        path.chmod(0o755)
    lines = ["# zig targeting %s (tools/cross_deps.py)" % spec["zig"],
             "set(CMAKE_SYSTEM_NAME %s)" % spec["system"], "set(CMAKE_SYSTEM_PROCESSOR %s)" % spec["processor"],
             "set(CMAKE_C_COMPILER %s/zcc)" % bin_dir, "set(CMAKE_CXX_COMPILER %s/zc++)" % bin_dir,
             "set(CMAKE_AR %s/zar)" % bin_dir, "set(CMAKE_RANLIB %s/zranlib)" % bin_dir]
    if spec["system"] == "Windows":
        rc = bin_dir / "zwindres"
        rc.write_text(RC_WRAPPER % {"cache": str(cache), "python": str(python)})
        rc.chmod(0o755)
        lines.append("set(CMAKE_RC_COMPILER %s)" % rc)
    else:
        # No SDK here: zig brings the headers and libSystem's stubs; the target's
        # version (11.0) is the minimum macOS.
        lines += ["set(CMAKE_OSX_SYSROOT \"\")", "set(CMAKE_OSX_DEPLOYMENT_TARGET \"\")",
                  "set(CMAKE_OSX_ARCHITECTURES \"\")",
                  # CMake wants Apple's install_name_tool for projects with C (GoogleTest's):
                  # nothing here is installed, so nothing needs a new install name.
                  "set(CMAKE_INSTALL_NAME_TOOL %s)" % shutil.which("true")]
    (folder / "zig.cmake").write_text("\n".join(lines) + "\n")


def portable_deps_folder(build):
    return Path(build).resolve() / "portable-deps"


def embree_options(platform):
    options = list(portable_deps.EMBREE_OPTIONS)
    if PLATFORMS[platform]["processor"] == "arm64":
        options = [o for o in options if not o.startswith("-DEMBREE_ISA_")] + ARM_ISA
    # The fixes' files named in the options: a build without them is not reused.
    if PLATFORMS[platform]["system"] == "Windows":
        options += WINDOWS_EMBREE + ["-DRADIOSITY_CROSS_FIXES=%s" % ",".join(sorted(EMBREE_WINDOWS_FIXES))]
    else:
        options += ["-DRADIOSITY_CROSS_FIXES=%s" % ",".join(sorted(EMBREE_STATIC_VISIBILITY_FIXES))]
    return options


def tbb_options(folder, platform):
    options = list(portable_deps.TBB_OPTIONS)
    if PLATFORMS[platform]["system"] == "Windows":
        header = folder / "tbb_static_exports.h"
        header.write_text(TBB_STATIC_EXPORTS)
        options.append("-DCMAKE_CXX_FLAGS=-include %s" % header)
    else:
        options += DARWIN_TBB
    return options


def fix_sources(source, fixes):
    """Apply (old, new) replacements to files under `source`, once (a no-op when applied)."""
    for rel, (old, new) in fixes.items():
        path = source / rel
        text = path.read_text()
        if new in text:
            continue
        if old not in text:
            sys.exit("error: %s changed; the fix for the cross build no longer applies" % path)
        path.write_text(text.replace(old, new))


def build(build_dir, platform):
    """Embree and oneTBB static for `platform`; returns its folder (the CMake prefix)."""
    shared = portable_deps_folder(build_dir)
    shared.mkdir(parents=True, exist_ok=True)
    portable_deps.zig(shared)             # the one zig, shared with the Linux build
    src = portable_deps.sources(shared)   # the one copy of the Debian sources
    folder = folder_of(build_dir, platform)
    toolchain(build_dir, platform)
    start = time.perf_counter()
    if PLATFORMS[platform]["system"] == "Windows":
        fix_sources(src["embree"], EMBREE_WINDOWS_FIXES)
    else:
        fix_sources(src["embree"], EMBREE_STATIC_VISIBILITY_FIXES)
    portable_deps.build_static(folder, "onetbb", src["onetbb"], tbb_options(folder, platform))
    portable_deps.build_static(folder, "embree", src["embree"], embree_options(platform))
    log("%s: Embree and oneTBB ready in %s (%.0f s)" % (platform, folder, time.perf_counter() - start))
    return folder


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("platforms", nargs="+", choices=PLATFORMS)
    args = parser.parse_args()
    for platform in args.platforms:
        build(args.build, platform)
    return 0


if __name__ == "__main__":
    sys.exit(main())
