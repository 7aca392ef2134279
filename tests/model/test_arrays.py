"""The add-on's array logic (addon/model/arrays.py) in plain Python: no Blender needed.

run_tests.py puts build/addon/radiosity on sys.path, where model/arrays.py is
copied by the build; it imports only numpy.
"""

import math
import unittest

import numpy as np

from model import arrays


def polygon_area_normal(points):
    """Area and unit normal (right-hand rule) of a planar polygon."""
    n = np.zeros(3)
    for a, b in zip(points, np.roll(points, -1, axis=0)):
        n += np.cross(a, b)
    return np.linalg.norm(n) / 2, n / np.linalg.norm(n)


class AreaLightTest(unittest.TestCase):
    def test_factor_by_version(self):
        self.assertEqual(arrays.area_light_factor((3, 4, 1)), 0.25)
        self.assertAlmostEqual(arrays.area_light_factor((4, 1, 0)), 1 / math.pi)

    def test_radiance_with_exposure_and_normalize(self):
        colour = (1.0, 0.5, 0.25)
        np.testing.assert_allclose(arrays.area_light_radiance((3, 4, 1), 10.0, 0.5, colour),
                                   [5.0, 2.5, 1.25])
        np.testing.assert_allclose(arrays.area_light_radiance((4, 5, 0), 10.0, 0.5, colour, exposure=2.0),
                                   np.multiply(colour, 4 * 10.0 / (math.pi * 0.5)))
        # Not normalized: the power is not spread over the area.
        np.testing.assert_allclose(arrays.area_light_radiance((4, 5, 0), 10.0, 0.5, colour, normalize=False),
                                   np.multiply(colour, 10.0 / math.pi))

    def test_shapes_face_down_with_the_ideal_area(self):
        for shape, sx, sy, area in (('SQUARE', 0.5, 9.0, 0.25), ('RECTANGLE', 0.5, 0.2, 0.1),
                                    ('DISK', 0.5, 9.0, math.pi * 0.0625),
                                    ('ELLIPSE', 0.5, 0.2, math.pi * 0.25 * 0.1)):
            with self.subTest(shape=shape):
                points, ideal = arrays.area_light_polygon(shape, sx, sy)
                self.assertAlmostEqual(ideal, area, places=12)
                got, normal = polygon_area_normal(points)
                # Round shapes: the polygon is grown to emit the same power.
                self.assertAlmostEqual(got, area, places=12)
                np.testing.assert_allclose(normal, [0, 0, -1], atol=1e-12)

    def test_scaled_area(self):
        m = np.diag([2.0, 3.0, 5.0, 1.0])
        m[:3, 3] = (1, 2, 3)
        self.assertAlmostEqual(arrays.scaled_area(m, 0.5), 3.0)

    def test_unknown_shape(self):
        with self.assertRaises(ValueError):
            arrays.area_light_polygon('TRIANGLE', 1, 1)


class PolygonArraysTest(unittest.TestCase):
    def test_polygon_corners_follow_loop_start(self):
        # Two polygons whose loops are stored out of order.
        loop_vertex = np.array([7, 8, 9, 1, 2, 3, 4])
        corners = arrays.polygon_corners([3, 0], [4, 3], loop_vertex)
        np.testing.assert_array_equal(corners, [1, 2, 3, 4, 7, 8, 9])

    def test_reverse_polygons(self):
        np.testing.assert_array_equal(arrays.reverse_polygons([0, 1, 2, 3, 4, 5, 6], [4, 3]),
                                      [3, 2, 1, 0, 6, 5, 4])

    def test_srgb(self):
        np.testing.assert_allclose(arrays.srgb_to_linear([0.0, 0.04045, 0.5, 1.0]),
                                   [0.0, 0.04045 / 12.92, 0.21404114, 1.0], rtol=1e-6)

    def test_normals_and_offset(self):
        p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 0], [0, 1, 0], [1, 0, 0.0]])
        fv = np.array([0, 1, 2, 3, 4, 5, 6])
        np.testing.assert_allclose(arrays.polygon_normals(p, fv, [4, 3]), [[0, 0, 1], [0, 0, -1]], atol=1e-12)
        moved = arrays.offset_sides(p, fv, [4, 3], 0.01)
        np.testing.assert_allclose(moved[:4, 2], 0.01)
        np.testing.assert_allclose(moved[4:, 2], -0.01)


class SceneBuilderTest(unittest.TestCase):
    def test_parts_concatenate(self):
        b = arrays.SceneBuilder()
        quad = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
        self.assertEqual(b.add(quad, [0, 1, 2, 3], [4], [0.5, 0.5, 0.5], [0, 0, 0], True), 0)
        self.assertEqual(b.add(quad + [0, 0, 1], [0, 1, 2, 0, 2, 3], [3, 3], [[2, 0, 0], [0.1, 0.2, 0.3]],
                               [1, 1, 1], False), 1)
        a = b.arrays()
        self.assertEqual(a["positions"].shape, (8, 3))
        np.testing.assert_array_equal(a["face_vertices"], [0, 1, 2, 3, 4, 5, 6, 4, 6, 7])
        np.testing.assert_array_equal(a["face_sizes"], [4, 3, 3])
        np.testing.assert_array_equal(a["face_part"], [0, 1, 1])
        np.testing.assert_array_equal(a["two_sided"], [True, False, False])
        self.assertEqual(a["reflectance"].max(), 1.0)   # clipped into [0, 1]

    def test_polygons_are_faces_of_their_own(self):
        b = arrays.SceneBuilder()
        self.assertEqual(b.polygon([(0, 0, 0), (1, 0, 0), (0, 1, 0)]), 0)
        self.assertEqual(b.polygon([(0, 0, 1), (1, 0, 1), (1, 1, 1), (0, 1, 1)], (0.2, 0.3, 0.4), 5.0, False), 1)
        a = b.arrays()
        np.testing.assert_array_equal(a["face_vertices"], [0, 1, 2, 3, 4, 5, 6])
        np.testing.assert_array_equal(a["face_sizes"], [3, 4])
        np.testing.assert_array_equal(a["reflectance"], [[0.5, 0.5, 0.5], [0.2, 0.3, 0.4]])
        np.testing.assert_array_equal(a["emission"], [[0, 0, 0], [5, 5, 5]])
        np.testing.assert_array_equal(a["two_sided"], [True, False])

    def test_empty(self):
        a = arrays.SceneBuilder().arrays()
        self.assertEqual(a["positions"].shape, (0, 3))
        self.assertEqual(len(a["face_sizes"]), 0)


class ResultArraysTest(unittest.TestCase):
    # A solved "mesh": face 0 split into two triangles (front side), face 1 one quad (back side).
    positions = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0],
                          [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1.0]])
    face_vertices = np.array([0, 1, 2, 0, 2, 3, 4, 5, 6, 7])
    face_sizes = np.array([3, 3, 4])
    source_face = np.array([0, 0, 1])
    source_side = np.array([0, 0, 1])
    radiance = np.arange(24, dtype=float).reshape(8, 3)

    def test_split_by_part(self):
        pieces = arrays.split_result(self.face_vertices, self.face_sizes, np.array([1, 1, 0]), 3)
        self.assertIsNone(pieces[2])
        polygons, vertices, local = pieces[1]
        np.testing.assert_array_equal(polygons, [0, 1])
        np.testing.assert_array_equal(vertices, [0, 1, 2, 3])
        np.testing.assert_array_equal(local, [0, 1, 2, 0, 2, 3])
        np.testing.assert_array_equal(pieces[0][1], [4, 5, 6, 7])

    def test_corner_values_match_positions(self):
        # Input faces: face 0 a quad whose corners are result vertices 0..3 (given in
        # another order), face 1 the upper quad.
        points = self.positions[[1, 2, 3, 0, 4, 5, 6, 7]] + 1e-12
        values, unmatched = arrays.corner_values(
            points, [4, 4], [0, 1], self.positions, self.face_vertices, self.face_sizes,
            self.source_face, self.source_side, self.radiance, tolerance=1e-7)
        self.assertEqual(unmatched, 0)
        np.testing.assert_allclose(values, self.radiance[[1, 2, 3, 0, 4, 5, 6, 7]])

    def test_unmatched_corner_takes_the_face_mean(self):
        points = np.array([[0.5, 0.5, 1.0], [1, 0, 1], [1, 1, 1], [0, 1, 1]])
        values, unmatched = arrays.corner_values(
            points, [4], [1], self.positions, self.face_vertices, self.face_sizes,
            self.source_face, self.source_side, self.radiance, tolerance=1e-7)
        self.assertEqual(unmatched, 1)
        np.testing.assert_allclose(values[0], self.radiance[4:].mean(axis=0))


if __name__ == "__main__":
    unittest.main()
