"""The ray pass (native/core/solve/ray_pass.h): what a solve stopped while it
links returns. A time or memory budget that runs out, or Esc, before the first
pass used to leave every surface black (a furnished house: -100 % exposure,
bench/furnished/README.md); it must leave the scene lit right in brightness.

Each test stops the solve at the report that carries the ray pass's result
(phase "linking", before any link is made): deterministic, whatever the
machine's speed.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))
sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[2] / "bench"))

import _radiosity as rad  # noqa: E402
from solver_bench import office  # noqa: E402
from synthetic_scenes import add_box, room_with_blocker  # noqa: E402
from test_energy import LAMP_RADIANCE, lit_room  # noqa: E402
from test_lights import scene_of  # noqa: E402
from test_solver import absorbed_power, closed_box, polygon_areas  # noqa: E402

LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def stopped_while_linking(scene, **options):
    """The solve cancelled as soon as the ray pass's result is reported."""
    token = rad.CancelToken()
    seen = []

    def progress(report):
        if report["phase"] == "linking" and "result" in report:
            seen.append(report["links"])
            token.cancel()

    result = rad.solve(scene, progress=progress, cancel=token, pass_results=True, **options)
    return result, seen


def exposure(result):
    """Area-weighted mean luminance of the polygons' gathered light."""
    areas = polygon_areas(result)
    return float((result.irradiance @ LUMINANCE * areas).sum() / areas.sum())


class RoughLook(unittest.TestCase):
    def test_it_comes_before_any_link_and_is_what_a_stop_returns(self):
        b = room_with_blocker()[0]
        result, seen = stopped_while_linking(b.scene(rad))
        self.assertEqual(seen, [0])  # reported once, before linking
        s = result.stats
        self.assertEqual((s["stopped_by"], s["passes"], s["links"]), ("cancel", 0, 0))
        self.assertGreaterEqual(s["ray_pass_rays"], 32)
        self.assertGreater(len(result.face_sizes), 0)
        self.assertTrue(np.isfinite(result.radiance).all())
        self.assertGreater(exposure(result), 0.0)

    def test_furnace(self):
        # Every face of a closed box emits 0.7 and reflects rho: L = 0.7 / (1 - rho)
        # everywhere. Each element's light is a mean of rays: noisy, not biased.
        for rho in (0.5, 0.9):
            with self.subTest(rho=rho):
                result, _ = stopped_while_linking(closed_box(rho, 0.7).scene(rad))
                ratio = result.radiance / (0.7 / (1 - rho))
                areas = polygon_areas(result)
                print("[rough furnace] rho %.1f: worst %.4f, mean %.5f" % (rho, np.abs(ratio - 1).max(),
                                                                          ratio.mean()), flush=True)
                self.assertLess(np.abs(ratio - 1).max(), 0.05)
                self.assertAlmostEqual(float(ratio.mean()), 1.0, delta=0.01)
                self.assertGreater(areas.min(), 0.0)

    def test_a_closed_room_absorbs_what_its_lamp_emits(self):
        emitted = math.pi * LAMP_RADIANCE * 0.36
        for rho in (0.5, 0.9):
            with self.subTest(rho=rho):
                b = lit_room(rho)
                result, _ = stopped_while_linking(b.scene(rad))
                ratio = absorbed_power(b, result)[1] / emitted
                print("[rough balance] rho %.1f: absorbed / emitted %.4f" % (rho, ratio), flush=True)
                self.assertAlmostEqual(ratio, 1.0, delta=0.01 if rho < 0.6 else 0.02)

    def test_brightness_within_five_percent_of_the_solved(self):
        # An area light over furniture; a shadowing plate and a box, with a point light too.
        lit = room_with_blocker()[0]
        add_box(lit, (0.3, 0.3, 0.0), (1.0, 1.0, 0.8), reflectance=0.4)
        lights = [{"type": "point", "position": (1.0, 3.0, 2.0), "intensity": (30.0, 25.0, 20.0)}]
        for name, scene in (("office", office().scene(rad)), ("room_with_blocker", lit.scene(rad)),
                            ("point light", scene_of(lit, lights=lights))):
            with self.subTest(scene=name):
                rough, _ = stopped_while_linking(scene, quality=0.5, visibility="sampled")
                solved = rad.solve(scene, quality=0.5, visibility="sampled")
                error = exposure(rough) / exposure(solved) - 1
                print("[rough exposure] %s: %+.2f %%" % (name, 100 * error), flush=True)
                self.assertLess(abs(error), 0.05)

    def test_deterministic_and_independent_of_threads(self):
        scene = office().scene(rad)
        one, _ = stopped_while_linking(scene, threads=1)
        two, _ = stopped_while_linking(scene, threads=2)
        np.testing.assert_array_equal(one.radiance, two.radiance)

    def test_a_solve_that_links_returns_the_solved_light(self):
        b = room_with_blocker()[0]
        result = rad.solve(b.scene(rad), quality=0.5)
        self.assertEqual(result.stats["stopped_by"], "quality")
        self.assertGreater(result.stats["passes"], 0)
        self.assertGreater(result.stats["links"], 0)


if __name__ == "__main__":
    unittest.main()
