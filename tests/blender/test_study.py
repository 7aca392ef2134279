"""Smoke test of the speed-accuracy study (bench/study.py, `make bench`): its
smallest mode (the cube, three solves per oracle, 96 x 72 snapshots, a few
path-traced samples, one Cycles bake) writes every file, and its numbers are
sane: errors finite, the refined reference scores zero against itself,
refining lowers the error, every solve's exposure error (mean linear luminance
against the path-traced reference) is what its snapshot shows and is stated
in every table of the report, the reference's noise is measured.

Runs the study as the bench does, with Debian's /usr/bin/python3 (or
$RADIOSITY_PYTHON), the build this Blender loaded the add-on from, and this
Blender; about a minute.
"""

import csv
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

import bpy
import numpy as np

import radiosity

ROOT = pathlib.Path(__file__).resolve().parents[2]
BUILD = pathlib.Path(radiosity.__file__).resolve().parents[2]   # <build>/addon/radiosity/__init__.py
sys.path.insert(0, str(ROOT / "bench"))
import study_config  # noqa: E402  (the oracles the study compares)

PYTHON = os.environ.get("RADIOSITY_PYTHON", "/usr/bin/python3" if os.path.exists("/usr/bin/python3")
                        else sys.executable)


class StudySmokeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="study-smoke-")
        cls.out = pathlib.Path(cls.tmp.name)
        cmd = [PYTHON, str(ROOT / "bench" / "study.py"), "--build", str(BUILD), "--blender", bpy.app.binary_path,
               "--mode", "smoke", "--out", str(cls.out)]
        cls.proc = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL, timeout=600)
        if cls.proc.returncode == 0:
            with open(cls.out / "study.csv") as f:
                cls.rows = list(csv.DictReader(f))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def setUp(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stdout[-3000:] + self.proc.stderr[-3000:])

    def radiosity(self, oracle):
        rows = [r for r in self.rows if r["method"] == "radiosity" and r["oracle"] == oracle]
        return sorted(rows, key=lambda r: int(r["leaves"]))

    def test_writes_every_file(self):
        for name in ("study.csv", "report.md", "study_error_vs_elements.png", "study_error_vs_time.png",
                     "study_error_vs_vertices.png", "study_elements_vs_time.png", "study_compare_cube.png"):
            path = self.out / name
            self.assertTrue(path.exists() and path.stat().st_size > 0, name)
        report = (self.out / "report.md").read_text()
        for heading in ("Elements and time at equal error", "Time against elements", "Cycles bake"):
            self.assertIn(heading, report)

    def test_every_oracle_swept_with_distinct_sizes(self):
        for oracle in study_config.ORACLES:
            rows = self.radiosity(oracle)
            self.assertGreaterEqual(len(rows), 3, oracle)
            self.assertLess(int(rows[0]["leaves"]), int(rows[-1]["leaves"]), oracle)
            for r in rows:
                self.assertGreater(float(r["seconds"]), 0.0)
                self.assertGreater(int(r["links"]), 0)

    def test_errors_are_finite_and_the_reference_scores_zero(self):
        for r in self.rows:
            for key in ("dog_refined", "rms_refined", "dog_cycles", "rms_cycles"):
                v = float(r[key])
                self.assertTrue(math.isfinite(v) and v >= 0.0, (r["method"], r["oracle"], key, v))
            self.assertTrue(math.isfinite(float(r["exposure_cycles"])), r)
        refined = [r for r in self.rows if r["method"] == "refined"]
        self.assertEqual(len(refined), 1)
        self.assertEqual(float(refined[0]["dog_refined"]), 0.0)
        self.assertEqual(float(refined[0]["rms_refined"]), 0.0)

    def test_refining_lowers_the_error_against_the_refined_reference(self):
        for oracle in study_config.ORACLES:
            rows = self.radiosity(oracle)
            for key in ("dog_refined", "rms_refined"):
                self.assertGreater(float(rows[0][key]), float(rows[-1][key]), (oracle, key))

    def test_exposure_error_of_every_solve_against_the_path_traced_reference(self):
        # The study-only module, beside the add-on, is built for the Python the
        # study runs in (Debian's Blender's), not for every Blender tested.
        import sysconfig
        built = [p.name for p in (BUILD / "study").glob("_image_metric*")]
        if not any(name.endswith(sysconfig.get_config_var("EXT_SUFFIX")) for name in built):
            self.skipTest("the study module is built for another Python (%s)" % ", ".join(built))
        sys.path.insert(0, str(BUILD / "study"))
        import _image_metric as metric
        images = self.out / "study" / "cube" / "images"
        keep = ~np.load(images / "emitter_mask.npy")
        cycles = metric.brightness(metric.read_image(str(images / "cycles.exr")), "linear")[keep].mean()
        for r in self.rows:
            # Recomputed here from the snapshot: mean linear luminance, emitter pixels out, signed.
            lum = metric.brightness(metric.read_image(str(self.out / r["image"])), "linear")[keep].mean()
            self.assertAlmostEqual(float(r["exposure_cycles"]), lum / cycles - 1, delta=1e-5, msg=r["image"])
        refined = [r for r in self.rows if r["method"] == "refined"][0]
        # The solver is a few per cent dark in closed rooms (test_cycles.py); a wrong
        # light convention or view transform would be off by far more.
        self.assertLess(abs(float(refined["exposure_cycles"])), 0.1)
        # It is reported beside DoG and RMS in every table of the report.
        report = (self.out / "report.md").read_text()
        tables = [block for block in report.split("\n\n") if block.startswith("| scene")]
        self.assertGreaterEqual(len(tables), 8)
        for table in tables:
            self.assertIn("exposure", table.splitlines()[0], table.splitlines()[0])
        self.assertIn("%+.1f %%" % (100 * float(refined["exposure_cycles"])), report)

    def test_cycles_bake_scored(self):
        bakes = [r for r in self.rows if r["method"] == "cycles_bake"]
        self.assertEqual(len(bakes), 1)
        self.assertGreater(int(bakes[0]["vertices"]), 100)
        self.assertGreater(float(bakes[0]["seconds"]), 0.0)
        # A bake of the same scene is close to the path-traced reference, never wildly off.
        self.assertLess(float(bakes[0]["rms_cycles"]), 0.2)


if __name__ == "__main__":
    unittest.main()
