"""Python access to the form-factor kernels: values, gradients and input validation.

The C++ unit tests (native/tests/form_factor_test.cpp) prove the kernels
themselves; these prove the binding carries the numbers across unchanged and
turns every bad argument into a ValueError that names it.
"""

import math
import unittest

import numpy as np

import _radiosity as rad

UP = np.array([0.0, 0.0, 1.0])
# Unit square at z = 1 facing down (counter-clockwise about -z).
SQUARE = np.array([[-0.5, -0.5, 1.0], [-0.5, 0.5, 1.0], [0.5, 0.5, 1.0], [0.5, -0.5, 1.0]])


def corner_parallel(a, b, c):
    """Closed form for a point below the corner of a parallel a x b rectangle at height c."""
    x, y = a / c, b / c
    sx, sy = math.sqrt(1 + x * x), math.sqrt(1 + y * y)
    return (x / sx * math.atan(y / sx) + y / sy * math.atan(x / sy)) / (2 * math.pi)


class FormFactorValues(unittest.TestCase):
    def test_centred_square_matches_closed_form(self):
        f = rad.form_factor([0, 0, 0], UP, SQUARE)
        self.assertAlmostEqual(f, 4 * corner_parallel(0.5, 0.5, 1.0), places=14)
        self.assertAlmostEqual(f, 0.23945647046077351, places=14)

    def test_gradient_matches_reference_and_finite_differences(self):
        f, g = rad.form_factor_gradient([0, 0, 0], UP, SQUARE)
        self.assertAlmostEqual(f, 0.23945647046077351, places=14)
        self.assertEqual(g.shape, (3,))
        self.assertEqual(g.dtype, np.float64)
        np.testing.assert_allclose(g, [0, 0, 0.361330448999974], atol=1e-13)

        point = np.array([0.13, -0.21, 0.05])
        normal = np.array([0.1, -0.2, 1.0]) / math.sqrt(1.05)
        _, g = rad.form_factor_gradient(point, normal, SQUARE)
        h = 1e-6
        fd = [(rad.form_factor(point + h * e, normal, SQUARE) - rad.form_factor(point - h * e, normal, SQUARE)) / (2 * h)
              for e in np.eye(3)]
        np.testing.assert_allclose(g, fd, rtol=1e-7, atol=1e-12)

    def test_accepts_lists_other_dtypes_and_unnormalised_normals(self):
        f_list = rad.form_factor([0, 0, 0], [0, 0, 5], SQUARE.tolist())
        f_float32 = rad.form_factor(np.zeros(3, np.float32), UP, SQUARE)
        self.assertAlmostEqual(f_list, 0.23945647046077351, places=14)
        self.assertAlmostEqual(f_float32, 0.23945647046077351, places=14)

    def test_behind_the_emitter_is_zero(self):
        self.assertEqual(rad.form_factor([0, 0, 2], UP, SQUARE), 0.0)
        f, g = rad.form_factor_gradient([0, 0, 1], UP, SQUARE)
        self.assertEqual(f, 0.0)
        self.assertTrue(np.all(g == 0))


class FormFactorValidation(unittest.TestCase):
    def assert_value_error(self, pattern, *args):
        for kernel in (rad.form_factor, rad.form_factor_gradient):
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


if __name__ == "__main__":
    unittest.main()
