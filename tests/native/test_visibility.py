"""Python access to occluded form factors: visible_form_factor(), exact and sampled.

The C++ tests (native/core/visibility/visibility_test.cpp, shaft_test.cpp) prove the visible
polygon, its gradient, the sampled mode and shaft culling; these prove the binding
carries the numbers across and turns every bad argument into a ValueError.
Run by tests/run_tests.py with build/addon/radiosity on sys.path.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from kernels_module import MISSING, kernels  # noqa: E402

# MATH.md section 5, occlusion case.
EMITTER = np.array([[-0.5, -0.5, 2.0], [-0.5, 0.5, 2.0], [0.5, 0.5, 2.0], [0.5, -0.5, 2.0]])
OCCLUDER = np.array([[[0.10, 0.05, 1.00], [0.45, -0.10, 0.90], [0.40, 0.20, 1.15]]])
POINT = np.array([0.03, -0.02, 0.0])
NORMAL = np.array([0.1, -0.2, 1.0]) / math.sqrt(1.05)


@unittest.skipIf(kernels is None, MISSING)
class ExactMode(unittest.TestCase):
    def test_math_occlusion_case(self):
        f, g = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER)
        self.assertAlmostEqual(f, 0.067975166508788, places=13)
        self.assertEqual(g.shape, (3,))
        self.assertEqual(g.dtype, np.float64)
        np.testing.assert_allclose(g, [-0.02685189, 0.00306648, 0.06437021], atol=1e-8)

    def test_gradient_matches_finite_differences(self):
        h = 1e-5
        _, g = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER)
        fd = [(kernels.visible_form_factor(POINT + h * e, NORMAL, EMITTER, OCCLUDER)[0]
               - kernels.visible_form_factor(POINT - h * e, NORMAL, EMITTER, OCCLUDER)[0]) / (2 * h)
              for e in np.eye(3)]
        np.testing.assert_allclose(g, fd, rtol=1e-6, atol=1e-10)

    def test_no_occluders_is_the_unoccluded_form_factor(self):
        expected, expected_g = kernels.form_factor_gradient(POINT, NORMAL, EMITTER)
        for empty in ([], np.zeros((0, 3, 3)), None):
            f, g = kernels.visible_form_factor(POINT, NORMAL, EMITTER, empty)
            self.assertEqual(f, expected)
            np.testing.assert_array_equal(g, expected_g)

    def test_accepts_lists_and_other_dtypes(self):
        f_list, _ = kernels.visible_form_factor(POINT.tolist(), NORMAL.tolist(), EMITTER.tolist(), OCCLUDER.tolist())
        f_f32, _ = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER.astype(np.float32))
        self.assertAlmostEqual(f_list, 0.067975166508788, places=13)
        self.assertAlmostEqual(f_f32, 0.067975166508788, places=6)

    def test_full_blocker_hides_everything(self):
        wall = np.array([[[-5, -5, 1], [5, -5, 1], [5, 5, 1]], [[-5, -5, 1], [5, 5, 1], [-5, 5, 1]]], float)
        f, g = kernels.visible_form_factor(POINT, NORMAL, EMITTER, wall)
        self.assertEqual(f, 0.0)
        self.assertTrue(np.all(g == 0))


@unittest.skipIf(kernels is None, MISSING)
class VisiblePolygonPieces(unittest.TestCase):
    def test_pieces_integrate_to_the_visible_form_factor(self):
        pieces, occluded = kernels.visible_polygon(POINT, NORMAL, EMITTER, OCCLUDER)
        self.assertTrue(occluded)
        total = sum(kernels.form_factor(POINT, NORMAL, p["positions"]) for p in pieces)
        f, _ = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER)
        self.assertAlmostEqual(total, f, places=14)
        kinds = [k for p in pieces for k in p["kinds"]]
        self.assertIn("apparent", kinds)
        # The occluder vertex seen inside the emitter is anchored at its 3D position.
        anchors = np.concatenate([p["anchors"] for p in pieces])
        self.assertTrue(np.any(np.all(np.abs(anchors - OCCLUDER[0, 0]) < 1e-12, axis=1)))
        for p in pieces:
            self.assertEqual(p["positions"].shape, p["anchors"].shape)
            np.testing.assert_allclose(p["positions"][:, 2], 2.0, atol=1e-12)

    def test_unoccluded_is_the_emitter(self):
        pieces, occluded = kernels.visible_polygon(POINT, NORMAL, EMITTER, [])
        self.assertFalse(occluded)
        self.assertEqual(len(pieces), 1)
        np.testing.assert_allclose(pieces[0]["positions"], EMITTER, atol=1e-15)


@unittest.skipIf(kernels is None, MISSING)
class SampledMode(unittest.TestCase):
    def test_converges_to_exact(self):
        exact, _ = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER)
        errors = []
        for rays in (16, 256, 4096, 65536):
            f, _ = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER, mode="sampled", rays=rays)
            errors.append(abs(f - exact))
        self.assertLess(errors[-1], 2e-4 * exact + 1e-6)
        self.assertLess(errors[-1], errors[0])

    def test_gradient_is_the_unoccluded_one_scaled(self):
        f0, g0 = kernels.form_factor_gradient(POINT, NORMAL, EMITTER)
        f, g = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER, mode="sampled", rays=256)
        np.testing.assert_allclose(g, g0 * (f / f0), rtol=1e-12)
        self.assertLess(f, f0)

    def test_deterministic(self):
        a = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER, mode="sampled", rays=100)
        b = kernels.visible_form_factor(POINT, NORMAL, EMITTER, OCCLUDER, mode="sampled", rays=100)
        self.assertEqual(a[0], b[0])


@unittest.skipIf(kernels is None, MISSING)
class Validation(unittest.TestCase):
    def check(self, message, **overrides):
        args = dict(point=POINT, normal=NORMAL, emitter=EMITTER, occluders=OCCLUDER)
        args.update(overrides)
        with self.assertRaisesRegex(ValueError, message):
            kernels.visible_form_factor(**args)

    def test_bad_shapes(self):
        self.check("point", point=[0, 0])
        self.check("emitter", emitter=EMITTER[:2])
        self.check("emitter", emitter=EMITTER[:, :2])
        self.check("occluders", occluders=OCCLUDER[0])
        self.check("occluders", occluders=np.zeros((2, 4, 3)))

    def test_non_finite(self):
        bad = OCCLUDER.copy()
        bad[0, 1, 2] = np.nan
        self.check("occluders", occluders=bad)
        self.check("point", point=[0, np.inf, 0])
        self.check("normal", normal=[0, 0, 0])

    def test_degenerate_or_unsupported_emitter(self):
        self.check("zero area", emitter=[[0, 0, 2], [1, 0, 2], [2, 0, 2]])
        self.check("not planar", emitter=[[0, 0, 2], [1, 0, 2], [1, 1, 2.5], [0, 1, 2]])
        self.check("not convex", emitter=[[0, 0, 2], [2, 0, 2], [0.5, 0.5, 2], [0, 2, 2]])
        # A repeated vertex made every visible piece NaN (make fuzz, issue 19).
        self.check("repeated vertex", emitter=[[-0.5, -0.5, 2], [-0.5, -0.5, 2], [0.5, 0.5, 2], [0.5, -0.5, 2]])

    def test_bad_mode_and_rays(self):
        self.check("mode", mode="approximate")
        self.check("rays", mode="sampled", rays=0)


if __name__ == "__main__":
    unittest.main()
