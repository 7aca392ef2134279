#!/usr/bin/env python3
"""The Khronos glTF validator (npm `gltf-validator`, pinned), installed into the build tree.

    python3 tools/gltf_validator.py install --build build        # once; a no-op after
    python3 tools/gltf_validator.py validate --build build FILE  # prints the JSON report

The validator is a JavaScript library; it is installed with npm into BUILD/node
(never globally) and run by tools/gltf_validate.js with Node.js, which
.ci/install-deps.sh installs when missing. `validate` installs it first if
needed, so a test can call it on a fresh machine. Exit code of `validate`: 0
without errors in the report, 1 with errors, 2 when the file cannot be validated.
"""

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCRIPT = ROOT / "tools" / "gltf_validate.js"
PACKAGE = "gltf-validator"
VERSION = "2.0.0-dev.3.10"


class ValidatorError(RuntimeError):
    """The validator cannot be installed or run; the message says why."""


def prefix(build):
    return Path(build).resolve() / "node"


def installed_version(build):
    package = prefix(build) / "node_modules" / PACKAGE / "package.json"
    try:
        return json.loads(package.read_text())["version"]
    except (OSError, ValueError, KeyError):
        return None


def install(build, quiet=False):
    """Install the pinned validator into BUILD/node unless it is there."""
    if installed_version(build) == VERSION:
        return
    npm = shutil.which("npm")
    if npm is None or shutil.which("node") is None:
        raise ValidatorError("Node.js and npm are needed for the glTF validator: "
                             "bash .ci/install-deps.sh (or make deps) installs them")
    if not quiet:
        print("Installing %s@%s into %s" % (PACKAGE, VERSION, prefix(build)), file=sys.stderr)
    prefix(build).mkdir(parents=True, exist_ok=True)
    proc = subprocess.run([npm, "install", "--prefix", str(prefix(build)), "--no-audit", "--no-fund",
                           "--save-exact", "%s@%s" % (PACKAGE, VERSION)],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    if proc.returncode != 0 or installed_version(build) != VERSION:
        raise ValidatorError("npm install %s@%s failed:\n%s" % (PACKAGE, VERSION, proc.stdout[-2000:]))


def validate(build, path):
    """The validator's report (a dict) on the .glb or .gltf at `path`."""
    install(build, quiet=True)
    proc = subprocess.run(["node", str(SCRIPT), "--modules", str(prefix(build) / "node_modules"), str(path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode not in (0, 1):
        raise ValidatorError("the glTF validator could not validate %s: %s" % (path, proc.stderr.strip()))
    return json.loads(proc.stdout)


def summary(report):
    """One line: the counts of the report's issues and the codes of its errors."""
    issues = report["issues"]
    codes = sorted({m["code"] for m in issues["messages"] if m["severity"] == 0})
    return "%d errors, %d warnings, %d infos, %d hints%s" % (
        issues["numErrors"], issues["numWarnings"], issues["numInfos"], issues["numHints"],
        " (%s)" % ", ".join(codes) if codes else "")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    sub = parser.add_subparsers(dest="command", required=True)
    p = sub.add_parser("install", help="install the pinned validator into BUILD/node")
    p.add_argument("--build", default="build")
    p = sub.add_parser("validate", help="print the validator's JSON report on FILE")
    p.add_argument("--build", default="build")
    p.add_argument("file")
    args = parser.parse_args()
    try:
        if args.command == "install":
            install(args.build)
            return 0
        report = validate(args.build, args.file)
    except ValidatorError as err:
        print("error:", err, file=sys.stderr)
        return 2
    print(json.dumps(report, indent=2))
    print(summary(report), file=sys.stderr)
    return 1 if report["issues"]["numErrors"] else 0


if __name__ == "__main__":
    sys.exit(main())
