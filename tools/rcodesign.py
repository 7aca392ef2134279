#!/usr/bin/env python3
"""rcodesign, the pure-Rust signer of Apple code (crates.io's apple-codesign, pinned),
built once with cargo into BUILD/cross/rcodesign; signs the macOS modules ad hoc
(tools/cross_build.py). Their signatures are checked by tests/platforms/code_signature.py:
`rcodesign verify` fails on every ad hoc signature (it parses the empty CMS blob).

Without its default feature (notarisation, which pulls in an AWS SDK): ad hoc
signing needs none of it. Needs cargo and rustc 1.81 or later
(rustup's, as on this project's machines; Debian 12's Rust 1.63 is too old).

    python3 tools/rcodesign.py install --build build      # prints its path
    python3 tools/rcodesign.py sign --build build FILE...
"""

import argparse
import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

CRATE = "apple-codesign"
VERSION = "0.29.0"


def folder(build):
    return Path(build).resolve() / "cross" / "rcodesign"


def executable(build):
    return folder(build) / "bin" / "rcodesign"


def cargo():
    found = shutil.which("cargo") or str(Path.home() / ".cargo" / "bin" / "cargo")
    if not os.access(found, os.X_OK):
        sys.exit("error: cargo not found: rcodesign (%s %s) is built with it; install Rust 1.81+ (rustup)"
                 % (CRATE, VERSION))
    return found


def install(build):
    """rcodesign's path, building it first when missing or of another version."""
    stamp = folder(build) / "version.txt"
    if executable(build).exists() and stamp.exists() and stamp.read_text() == VERSION:
        return executable(build)
    print("[rcodesign] building %s %s with cargo (minutes, once)" % (CRATE, VERSION), flush=True)
    start = time.perf_counter()
    log = folder(build).parent / "rcodesign-build.log"
    log.parent.mkdir(parents=True, exist_ok=True)
    with open(log, "w") as out:
        proc = subprocess.run([cargo(), "install", "%s@%s" % (CRATE, VERSION), "--locked", "--no-default-features",
                               "--root", str(folder(build)), "--force", "-j", str(os.cpu_count() or 1),
                               # its own target folder, kept: a build cut short resumes
                               # where it stopped (cargo install's temporary one is deleted)
                               "--target-dir", str(folder(build).parent / "rcodesign-target")],
                              stdout=out, stderr=subprocess.STDOUT)
    if proc.returncode != 0:
        sys.exit("error: cargo install %s failed; see %s:\n%s" % (CRATE, log, log.read_text()[-3000:]))
    stamp.write_text(VERSION)
    shutil.rmtree(folder(build).parent / "rcodesign-target", ignore_errors=True)   # 640 MB, of no more use
    print("[rcodesign] built in %.0f s" % (time.perf_counter() - start), flush=True)
    return executable(build)


def sign(build, path):
    """Sign `path` ad hoc in place (replacing the linker's signature, if any)."""
    subprocess.run([str(install(build)), "sign", str(path)], check=True, capture_output=True, text=True)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("action", choices=("install", "sign"))
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("files", nargs="*")
    args = parser.parse_args()
    if args.action == "install":
        print(install(args.build))
    for path in args.files:
        sign(args.build, path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
