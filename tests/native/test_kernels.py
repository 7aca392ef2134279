"""The form-factor kernels of the test-only _radiosity_kernels: values, gradients and input validation.

The C++ unit tests (native/core/geometry/form_factor_test.cpp) prove the kernels
themselves; these prove the binding carries the numbers across unchanged and
turns every bad argument into a ValueError that names it.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

from kernels_module import MISSING, kernels  # noqa: E402

UP = np.array([0.0, 0.0, 1.0])
# Unit square at z = 1 facing down (counter-clockwise about -z).
SQUARE = np.array([[-0.5, -0.5, 1.0], [-0.5, 0.5, 1.0], [0.5, 0.5, 1.0], [0.5, -0.5, 1.0]])


def corner_parallel(a, b, c):
    """Closed form for a point below the corner of a parallel a x b rectangle at height c."""
    x, y = a / c, b / c
    sx, sy = math.sqrt(1 + x * x), math.sqrt(1 + y * y)
    return (x / sx * math.atan(y / sx) + y / sy * math.atan(x / sy)) / (2 * math.pi)


@unittest.skipIf(kernels is None, MISSING)
class FormFactorValues(unittest.TestCase):
    def test_centred_square_matches_closed_form(self):
        f = kernels.form_factor([0, 0, 0], UP, SQUARE)
        self.assertAlmostEqual(f, 4 * corner_parallel(0.5, 0.5, 1.0), places=14)
        self.assertAlmostEqual(f, 0.23945647046077351, places=14)

    def test_gradient_matches_reference_and_finite_differences(self):
        f, g = kernels.form_factor_gradient([0, 0, 0], UP, SQUARE)
        self.assertAlmostEqual(f, 0.23945647046077351, places=14)
        self.assertEqual(g.shape, (3,))
        self.assertEqual(g.dtype, np.float64)
        np.testing.assert_allclose(g, [0, 0, 0.361330448999974], atol=1e-13)

        point = np.array([0.13, -0.21, 0.05])
        normal = np.array([0.1, -0.2, 1.0]) / math.sqrt(1.05)
        _, g = kernels.form_factor_gradient(point, normal, SQUARE)
        h = 1e-6
        fd = [(kernels.form_factor(point + h * e, normal, SQUARE) - kernels.form_factor(point - h * e, normal, SQUARE)) / (2 * h)
              for e in np.eye(3)]
        np.testing.assert_allclose(g, fd, rtol=1e-7, atol=1e-12)

    def test_accepts_lists_other_dtypes_and_unnormalised_normals(self):
        f_list = kernels.form_factor([0, 0, 0], [0, 0, 5], SQUARE.tolist())
        f_float32 = kernels.form_factor(np.zeros(3, np.float32), UP, SQUARE)
        self.assertAlmostEqual(f_list, 0.23945647046077351, places=14)
        self.assertAlmostEqual(f_float32, 0.23945647046077351, places=14)

    def test_behind_the_emitter_is_zero(self):
        self.assertEqual(kernels.form_factor([0, 0, 2], UP, SQUARE), 0.0)
        f, g = kernels.form_factor_gradient([0, 0, 1], UP, SQUARE)
        self.assertEqual(f, 0.0)
        self.assertTrue(np.all(g == 0))


@unittest.skipIf(kernels is None, MISSING)
class FormFactorValidation(unittest.TestCase):
    def assert_value_error(self, pattern, *args):
        for kernel in (kernels.form_factor, kernels.form_factor_gradient):
            with self.assertRaisesRegex(ValueError, pattern):
                kernel(*args)

    def test_bad_shapes(self):
        self.assert_value_error("point must have shape", [0, 0], UP, SQUARE)
        self.assert_value_error("normal must have shape", [0, 0, 0], [[0, 0, 1]], SQUARE)
        self.assert_value_error("polygon must have shape", [0, 0, 0], UP, SQUARE[:, :2])
        self.assert_value_error("polygon must have shape", [0, 0, 0], UP, SQUARE.ravel())

    def test_too_few_vertices(self):
        self.assert_value_error("at least 3 vertices", [0, 0, 0], UP, SQUARE[:2])
        self.assert_value_error("at least 3 vertices", [0, 0, 0], UP, np.zeros((0, 3)))

    def test_non_finite_values(self):
        bad = SQUARE.copy()
        bad[2, 1] = np.nan
        self.assert_value_error("polygon contains a non-finite", [0, 0, 0], UP, bad)
        self.assert_value_error("point contains a non-finite", [0, np.inf, 0], UP, SQUARE)
        self.assert_value_error("normal contains a non-finite", [0, 0, 0], [np.nan, 0, 1], SQUARE)

    def test_zero_normal_and_degenerate_polygons(self):
        self.assert_value_error("normal must be a non-zero", [0, 0, 0], [0, 0, 0], SQUARE)
        collinear = np.array([[0, 0, 1], [1, 0, 1], [2, 0, 1.0]])
        self.assert_value_error("zero area", [0, 0, 0], UP, collinear)
        self.assert_value_error("zero area", [0, 0, 0], UP, np.ones((4, 3)))

    def test_not_an_array(self):
        self.assert_value_error("polygon must be", [0, 0, 0], UP, None)
        self.assert_value_error("polygon must be", [0, 0, 0], UP, "square")

    def test_coordinates_beyond_the_scene_range(self):
        # Beyond kMaxCoordinate (1e30, include/radiosity/scene.h) the kernels' products of
        # lengths overflow (NaN visible-polygon anchors from 1e154 occluders).
        self.assert_value_error("point has a coordinate of magnitude", [0, 0, 1e31], UP, SQUARE)
        self.assert_value_error("polygon has a coordinate of magnitude", [0, 0, 0], UP, SQUARE * 1e31)
        occluder = np.array([[[0, 0, 0.5], [1e200, 0, 0.5], [0, 1, 0.5]]])
        for call in (kernels.visible_form_factor, kernels.visible_polygon):
            with self.assertRaisesRegex(ValueError, "occluders has a coordinate of magnitude"):
                call([0, 0, 0], UP, SQUARE, occluder)
        # At the limit itself the answer is finite: the unit square seen from 1e29 away.
        f, g = kernels.visible_form_factor([0, 0, 0], UP, SQUARE * 1e29, occluder / 1e171)
        self.assertTrue(np.isfinite(f) and np.all(np.isfinite(g)))


@unittest.skipIf(kernels is None, MISSING)
class FormFactorNearTheEmitter(unittest.TestCase):
    """Findings of the fuzzing campaign (issue 19): F of a planar convex emitter is in [0, 1]."""

    SLIVER = np.array([[9.99938964836474, -9.842458791099524, -9.99999999941564],
                       [2.8625488677062094, 2.862745098039216, 2.862745098039216],
                       [2.862745098039216, 2.862745098039216, 2.862745098039216]])

    def test_receiver_on_a_vertex_of_a_sliver_sees_nothing(self):
        # The sliver's normal, from its long edges, is off by 1e-11: a receiver
        # on vertex 2 was 2e-11 "in front" of v0's plane and got F = -0.033
        # (atheris, 109 findings in 600 s).
        n = np.array([-9.999999999999954, -7.490196078431373, -10.0])
        for point in (self.SLIVER[2], [2.862745098039219, 2.8627450980392064, 2.862745098039214]):
            self.assertEqual(kernels.form_factor(point, n, self.SLIVER), 0.0)
            self.assertEqual(kernels.form_factor_gradient(point, n, self.SLIVER)[0], 0.0)

    def test_tiny_polygon_matches_its_unit_scale_copy(self):
        # Rescaled below 2^-200 (products of four lengths underflow below 1e-77;
        # the C++ test goes to 1e-100, which read_polygon's area check refuses).
        for scale in (1e-70, 1e-40, 1.0):
            f, g = kernels.form_factor_gradient([0, 0, 0], UP, SQUARE * scale)
            self.assertAlmostEqual(f, 4 * corner_parallel(0.5, 0.5, 1.0), places=12)
            self.assertTrue(np.all(np.isfinite(g * scale)))


if __name__ == "__main__":
    unittest.main()
