"""Runs the unittest TestCases of one test file and writes the counts as JSON.

Used by run_tests.py in two places, so both report the same way:
- under /usr/bin/python3 for tests/native/ (the `_radiosity` module without Blender):
      python3 unittest_runner.py --path build/addon/radiosity FILE OUT.json
- inside Blender for tests/blender/, where arguments follow `--`:
      blender --background --factory-startup --python-exit-code 1 \
          --python unittest_runner.py -- --path build/addon --register radiosity FILE OUT.json

With --register MODULE the add-on is imported and registered before the tests
and unregistered after them; a failure there counts as a failed test.
The JSON holds: file, passed, failed, skipped, seconds, failures (id + traceback).
The exit code is 1 when anything failed, so a crash and a failure look alike
to a caller that only checks the code.
"""

import argparse
import faulthandler
import fnmatch
import importlib
import importlib.util
import json
import os
import sys
import time
import traceback
import unittest


def parse_args(argv):
    # Inside Blender, sys.argv holds Blender's own options before `--`.
    if "--" in argv:
        argv = argv[argv.index("--") + 1:]
    else:
        argv = argv[1:]
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--path", action="append", default=[],
                        help="directory to put on sys.path (repeatable)")
    parser.add_argument("--register", metavar="MODULE",
                        help="import MODULE and call its register() before the tests")
    parser.add_argument("-k", dest="patterns", action="append", default=[],
                        help="only run tests whose id matches (unittest -k rules)")
    parser.add_argument("testfile")
    parser.add_argument("json_out")
    return parser.parse_args(argv)


def matches(test_id, patterns):
    """unittest's -k rule: fnmatch if the pattern has a '*', else substring."""
    if not patterns:
        return True
    for pattern in patterns:
        if "*" in pattern:
            if fnmatch.fnmatchcase(test_id, pattern):
                return True
        elif pattern in test_id:
            return True
    return False


def iter_tests(suite):
    for item in suite:
        if isinstance(item, unittest.TestSuite):
            yield from iter_tests(item)
        else:
            yield item


def load_file(path):
    """Import a test file as a module named after it, with its folder on sys.path
    so that it can import helpers that sit beside it."""
    folder, name = os.path.split(os.path.abspath(path))
    sys.path.insert(0, folder)
    spec = importlib.util.spec_from_file_location(os.path.splitext(name)[0], path)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module
    spec.loader.exec_module(module)
    return module


class _ProgressOnly(unittest.TextTestResult):
    """Prints one line per test; the tracebacks go into the JSON report instead."""

    def printErrors(self):
        pass


class Report:
    def __init__(self, testfile):
        self.data = {"file": testfile, "passed": 0, "failed": 0, "skipped": 0,
                     "seconds": 0.0, "failures": []}

    def fail(self, test_id, text):
        self.data["failed"] += 1
        self.data["failures"].append({"id": test_id, "traceback": text})

    def add_result(self, result, ran):
        for test, text in result.failures + result.errors:
            self.fail(test.id() if hasattr(test, "id") else str(test), text)
        for test in result.unexpectedSuccesses:
            self.fail(test.id(), "unexpected success")
        self.data["skipped"] += len(result.skipped)
        # Each failing subTest is a failure of its own, but a test counts as
        # passed only if none of its subtests failed (so `passed` never goes
        # below zero when one test has many failing subtests).
        not_passed = {id(getattr(test, "test_case", test)) for test, _ in
                      result.failures + result.errors + result.skipped}
        not_passed |= {id(test) for test in result.unexpectedSuccesses}
        self.data["passed"] += ran - len(not_passed)


def main():
    args = parse_args(sys.argv)
    # A crash in native code then still shows the Python stack that led to it.
    faulthandler.enable()
    for path in reversed(args.path):
        sys.path.insert(0, os.path.abspath(path))
    report = Report(args.testfile)
    start = time.perf_counter()
    addon = None
    try:
        if args.register:
            try:
                addon = importlib.import_module(args.register)
                addon.register()
            except Exception:
                addon = None
                report.fail("register %s" % args.register, traceback.format_exc())
        if not report.data["failed"]:
            try:
                module = load_file(args.testfile)
            except Exception:
                report.fail("import %s" % args.testfile, traceback.format_exc())
            else:
                suite = unittest.defaultTestLoader.loadTestsFromModule(module)
                tests = [t for t in iter_tests(suite) if matches(t.id(), args.patterns)]
                # Progress goes to stderr, so that after a crash the caller's
                # log ends with the test that was running.
                runner = unittest.TextTestRunner(stream=sys.stderr, verbosity=2,
                                                 resultclass=_ProgressOnly)
                result = runner.run(unittest.TestSuite(tests))
                report.add_result(result, result.testsRun)
        if addon is not None:
            try:
                addon.unregister()
            except Exception:
                report.fail("unregister %s" % args.register, traceback.format_exc())
    finally:
        report.data["seconds"] = time.perf_counter() - start
        with open(args.json_out, "w", encoding="utf-8") as out:
            json.dump(report.data, out, indent=1)
    sys.exit(1 if report.data["failed"] else 0)


if __name__ == "__main__":
    main()
