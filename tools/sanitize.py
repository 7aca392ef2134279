#!/usr/bin/env python3
"""`make sanitize`: the native tests under AddressSanitizer and
UndefinedBehaviorSanitizer (issue 19).

Builds the C++ unit tests (radiosity_tests), the module `_radiosity` and the
study's `_image_metric` with GCC and -fsanitize=address,undefined
(-fno-sanitize-recover=all: the first report stops the process) into
BUILD/sanitize, then runs
  - ctest (the GoogleTest programs, leak checking on), and
  - every tests/native/test_*.py but test_package.py (which checks the shipped
    zips, not this build) with Debian's Python, which is not built with ASan:
    the runtime has to be loaded first, so libasan is preloaded (LD_PRELOAD)
    and leak checking is off (CPython keeps its objects at exit).
A test that fails, and any sanitizer report in any output, fails the run; the
reports are printed. The last line is `N passed, M failed`.

    python3 tools/sanitize.py --build build [--jobs 2] [-k PATTERN]
"""

import argparse
import json
import os
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
FLAGS = "-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer"
# A sanitizer's first line: ASan's "ERROR: AddressSanitizer", UBSan's "runtime error:",
# LeakSanitizer's "ERROR: LeakSanitizer".
REPORT = re.compile(r"ERROR: (Address|Leak)Sanitizer|runtime error:|SUMMARY: (Address|UndefinedBehavior|Leak)Sanitizer")
SKIP = {"test_package.py"}


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="the project's build directory (this uses BUILD/sanitize)")
    parser.add_argument("--python", default="/usr/bin/python3", help="the interpreter of the native tests")
    parser.add_argument("--jobs", type=int, default=2, help="compile jobs")
    parser.add_argument("-k", dest="patterns", action="append", default=[],
                        help="only test files whose name holds this (repeatable); ctest always runs")
    parser.add_argument("--timeout", type=float, default=3600, help="seconds per test file")
    return parser.parse_args()


def run(cmd, **kwargs):
    print("+ " + " ".join(str(c) for c in cmd), flush=True)
    return subprocess.run(cmd, check=True, **kwargs)


def build(args, folder):
    version = subprocess.run([args.python, "-c", "import sys; print('%d.%d' % sys.version_info[:2])"],
                             check=True, capture_output=True, text=True).stdout.strip()
    if not (folder / "CMakeCache.txt").exists():
        run(["cmake", "-S", ROOT, "-B", folder, "-DCMAKE_BUILD_TYPE=RelWithDebInfo",
             "-DRADIOSITY_PORTABLE=OFF", "-DRADIOSITY_BUILD_BENCHMARKS=OFF",
             "-DRADIOSITY_PYTHON_VERSION=%s" % version, "-DCMAKE_CXX_FLAGS=%s" % FLAGS],
            stdout=subprocess.DEVNULL)
    run(["cmake", "--build", folder, "-j", str(args.jobs), "--target",
         "radiosity_tests", "_radiosity", "addon", "_image_metric"])


def preload():
    """libasan first; libstdc++ too, so that ASan's __cxa_throw interceptor finds the
    real one when it starts (Python does not link libstdc++: without it the first
    C++ exception, a ValueError, aborts with "real___cxa_throw != 0")."""
    paths = []
    for name in ("libasan.so", "libstdc++.so"):
        path = subprocess.run(["gcc", "-print-file-name=%s" % name], check=True, capture_output=True,
                              text=True).stdout.strip()
        if not os.path.isabs(path):
            raise SystemExit("gcc does not know where %s is (%s)" % (name, path))
        paths.append(os.path.realpath(path))
    return " ".join(paths)


def reports(text):
    """The sanitizer reports in a process's output (each from its first line on, 30 lines)."""
    lines = text.splitlines()
    found = []
    for i, line in enumerate(lines):
        if REPORT.search(line) and not line.startswith("SUMMARY"):
            found.append("\n".join(lines[i:i + 30]))
    if not found and any(line.startswith("SUMMARY") and REPORT.search(line) for line in lines):
        found.append("\n".join(line for line in lines if REPORT.search(line)))
    return found


def run_ctest(folder):
    start = time.perf_counter()
    junit = folder / "ctest-junit.xml"
    env = dict(os.environ, ASAN_OPTIONS="detect_leaks=1:abort_on_error=1",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1")
    proc = subprocess.run(["ctest", "--test-dir", folder, "-j", "2", "--output-on-failure",
                           "--output-junit", junit, "--timeout", "1800"],
                          capture_output=True, text=True, env=env)
    out = proc.stdout + proc.stderr
    passed = len(re.findall(r"^\s*\d+/\d+ Test\s+#\d+: .* Passed", out, re.MULTILINE))
    failed = len(re.findall(r"^\s*\d+/\d+ Test\s+#\d+: .* (\*\*\*|Failed|Exception|Timeout)", out, re.MULTILINE))
    if proc.returncode != 0 and failed == 0:
        failed = 1
    found = reports(out)
    print("%-4s %-36s %4d passed %4d failed %7.1f s%s"
          % ("FAIL" if failed or found else "ok", "ctest (radiosity_tests)", passed, failed,
             time.perf_counter() - start, "  %d sanitizer reports" % len(found) if found else ""), flush=True)
    if failed and not found:
        print("\n".join("     | " + line for line in out.splitlines()[-40:]))
    return passed, failed, found


def run_python_tests(args, folder, tmp):
    env = dict(os.environ, LD_PRELOAD=preload(),
               ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:allocator_may_return_null=1",
               UBSAN_OPTIONS="print_stacktrace=1:halt_on_error=1",
               PYTHONFAULTHANDLER="1")
    total_passed = total_failed = 0
    all_found = []
    for testfile in sorted((ROOT / "tests" / "native").glob("test_*.py")):
        if testfile.name in SKIP or (args.patterns and not any(p in testfile.name for p in args.patterns)):
            continue
        out_json = Path(tmp) / (testfile.stem + ".json")
        cmd = [args.python, str(ROOT / "tests" / "unittest_runner.py"),
               "--path", str(folder / "addon" / "radiosity"), "--path", str(folder / "study"),
               str(testfile), str(out_json)]
        start = time.perf_counter()
        try:
            proc = subprocess.run(cmd, capture_output=True, text=True, env=env, timeout=args.timeout,
                                  stdin=subprocess.DEVNULL)
            out, code = proc.stdout + proc.stderr, proc.returncode
        except subprocess.TimeoutExpired as err:
            out, code = (err.stdout or b"").decode(errors="replace") + "\n[timed out]", None
        try:
            report = json.loads(out_json.read_text())
            passed, failed = report["passed"], report["failed"]
        except (OSError, ValueError):
            report, passed, failed = None, 0, 1
        if code != 0 and failed == 0:
            failed = 1
        found = reports(out)
        print("%-4s %-36s %4d passed %4d failed %7.1f s%s"
              % ("FAIL" if failed or found else "ok", "native/" + testfile.name, passed, failed,
                 time.perf_counter() - start, "  %d sanitizer reports" % len(found) if found else ""), flush=True)
        if failed and not found:
            details = "\n".join(f["traceback"] for f in report["failures"]) if report else out
            print("\n".join("     | " + line for line in details.splitlines()[-40:]))
        total_passed += passed
        total_failed += failed
        all_found += ["%s:\n%s" % (testfile.name, r) for r in found]
    return total_passed, total_failed, all_found


def main():
    args = parse_args()
    folder = (ROOT / args.build / "sanitize") if not os.path.isabs(args.build) else Path(args.build) / "sanitize"
    build(args, folder)
    passed, failed, found = run_ctest(folder)
    with tempfile.TemporaryDirectory(prefix="radiosity-sanitize-") as tmp:
        p, f, r = run_python_tests(args, folder, tmp)
    passed, failed, found = passed + p, failed + f, found + r
    for report in found:
        print("--- sanitizer report ---\n" + report)
    print("sanitizers: %s (%d reports)" % ("clean" if not found else "NOT clean", len(found)))
    if found and not failed:
        failed = 1
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed or found else 0


if __name__ == "__main__":
    sys.exit(main())
