"""UV maps carried onto the refined result (addon/model/surface_uv.py) in plain Python.

run_tests.py puts build/addon/radiosity on sys.path, where model/surface_uv.py is
copied by the build; it imports only numpy.
"""

import unittest

import numpy as np

from model import surface_uv


class LoopOrderTest(unittest.TestCase):
    def test_flat_order_and_mirroring(self):
        # Polygon 0 stored at loops 3..6, polygon 1 at loops 0..2.
        np.testing.assert_array_equal(surface_uv.flat_loop_order([3, 0], [4, 3]), [3, 4, 5, 6, 0, 1, 2])
        np.testing.assert_array_equal(surface_uv.flat_loop_order([3, 0], [4, 3], mirrored=True),
                                      [6, 5, 4, 3, 2, 1, 0])

    def test_loop_triangles_to_flat(self):
        flat = surface_uv.flat_loop_order([3, 0], [4, 3])
        tris = surface_uv.loop_triangles_to_flat([[3, 4, 5], [3, 5, 6], [0, 1, 2]], flat, 7)
        np.testing.assert_array_equal(tris, [[0, 1, 2], [0, 2, 3], [4, 5, 6]])
        uv = np.arange(14.0).reshape(7, 2)
        np.testing.assert_array_equal(surface_uv.loop_values_to_flat(uv, flat)[0], uv[3])

    def test_loop_uvs_in_corner_order(self):
        # A quad (loops 3..6) and a triangle (loops 0..2), mirrored.
        uv = np.arange(14.0).reshape(7, 2)
        loops = surface_uv.LoopUVs({"UVMap": uv}, "UVMap", [3, 0], [4, 3], [[3, 4, 5], [3, 5, 6], [0, 1, 2]],
                                   [0, 0, 1])
        layers, tris, face = loops.corners(mirrored=True)
        self.assertEqual(set(layers), {"UVMap"})
        self.assertEqual(layers["UVMap"].dtype, np.float32)
        np.testing.assert_array_equal(face, [0, 0, 1])
        flat = surface_uv.flat_loop_order([3, 0], [4, 3], mirrored=True)
        np.testing.assert_array_equal(flat, [6, 5, 4, 3, 2, 1, 0])
        np.testing.assert_array_equal(layers["UVMap"], uv[flat])
        # Each triangle's corners name the same loops as before.
        np.testing.assert_array_equal(flat[tris], [[3, 4, 5], [3, 5, 6], [0, 1, 2]])


class BlenderTrianglesTest(unittest.TestCase):
    def test_convex_quad_splits_along_0_2(self):
        p = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0], [0, 0, 0], [1, 0, 0], [0, 1, 0.0]])
        tris, face = surface_uv.blender_triangles(p, [4, 3])
        np.testing.assert_array_equal(tris, [[0, 1, 2], [0, 2, 3], [4, 5, 6]])
        np.testing.assert_array_equal(face, [0, 0, 1])

    def test_concave_quad_splits_along_1_3(self):
        # Corner 3 pushed inside triangle (0, 1, 2): the 0-2 diagonal lies
        # outside the quad, Blender flips to 1-3.
        p = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [1.5, 0.5, 0.0]])
        tris, _ = surface_uv.blender_triangles(p, [4])
        np.testing.assert_array_equal(tris, [[0, 1, 3], [1, 2, 3]])

    def test_ngon_fan(self):
        p = np.array([[np.cos(a), np.sin(a), 0] for a in np.linspace(0, 2 * np.pi, 6, endpoint=False)])
        tris, face = surface_uv.blender_triangles(p, [6])
        np.testing.assert_array_equal(tris, [[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]])
        np.testing.assert_array_equal(face, [0] * 4)


class InterpolateTest(unittest.TestCase):
    def test_affine_map_is_reproduced(self):
        # A planar pentagon in 3D with UV an affine function of position: any
        # point inside gets the affine value, from whichever triangle.
        rng = np.random.default_rng(1)
        angles = np.sort(rng.uniform(0, 2 * np.pi, 5))
        flat = np.column_stack([np.cos(angles), np.sin(angles)])
        frame = np.array([[0.3, 0.9, 0.1], [-0.8, 0.2, 0.5]])
        points = flat @ frame + [1, 2, 3]
        uv_of = lambda xy: xy @ [[2.0, 0.5], [-1.0, 3.0]] + [0.25, -0.5]  # noqa: E731
        tris, face = surface_uv.blender_triangles(points, [5])
        weights = rng.dirichlet(np.ones(5), size=50)
        query_xy = weights @ flat
        got = surface_uv.interpolate(points, [5], tris, face, uv_of(flat), query_xy @ frame + [1, 2, 3],
                                     np.zeros(50, dtype=int))
        np.testing.assert_allclose(got, uv_of(query_xy), atol=1e-12)

    def test_quad_uses_the_triangle_containing_the_point(self):
        # A square whose UVs are not affine (a seam-like stretch at corner 2):
        # along the 0-2 split, points of triangle (0, 2, 3) ignore corner 1.
        points = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0.0]])
        uv = np.array([[0, 0], [1, 0], [3, 3], [0, 1.0]])
        tris, face = surface_uv.blender_triangles(points, [4])
        q = np.array([[0.25, 0.75, 0.0], [0.75, 0.25, 0.0], [1.0, 1.0, 0.0]])
        got = surface_uv.interpolate(points, [4], tris, face, uv, q, [0, 0, 0])
        # (0.25, 0.75) = 0.25 * p0 + 0.25 * p2 + 0.5 * p3 ... in triangle (0, 2, 3):
        np.testing.assert_allclose(got[0], 0.25 * uv[0] + 0.25 * uv[2] + 0.5 * uv[3])
        np.testing.assert_allclose(got[1], 0.25 * uv[0] + 0.5 * uv[1] + 0.25 * uv[2])
        np.testing.assert_allclose(got[2], uv[2])

    def test_points_of_several_faces_and_offsets(self):
        # Two faces; points slightly off the plane (the sides' offset) and a
        # rounding outside the face still interpolate.
        points = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0.0],
                           [0, 0, 1], [0, 1, 1], [1, 0, 1.0]])
        uv = np.column_stack([points[:, 0] / 2, points[:, 1] / 2])
        uv[4:] = [[5, 5], [5, 6], [6, 5]]
        tris, face = surface_uv.blender_triangles(points, [4, 3])
        q = np.array([[0.5, 1.5, 1e-6], [2.0 + 1e-12, 1.0, 0.0], [0.25, 0.25, 1.0]])
        got = surface_uv.interpolate(points, [4, 3], tris, face, uv, q, [0, 0, 1])
        np.testing.assert_allclose(got, [[0.25, 0.75], [1.0, 0.5], [5.25, 5.25]], atol=1e-9)

    def test_degenerate_face_takes_the_corner_mean(self):
        points = np.array([[0, 0, 0], [1, 0, 0], [2, 0, 0.0]])
        tris, face = surface_uv.blender_triangles(points, [3])
        got = surface_uv.interpolate(points, [3], tris, face, np.array([1.0, 2.0, 6.0]), [[0.5, 0, 0]], [0])
        np.testing.assert_allclose(got, [3.0])

    def test_part_corner_queries(self):
        # Three result polygons: parts 1, 0, 1; part 1's input faces start at 10.
        vertices, faces = surface_uv.part_corner_queries([0, 1, 2, 3, 4, 5, 6, 7, 8, 9], [0, 3, 6], [3, 3, 4],
                                                         [0, 2], [10, 2, 11], 10)
        np.testing.assert_array_equal(vertices, [0, 1, 2, 6, 7, 8, 9])
        np.testing.assert_array_equal(faces, [0, 0, 0, 1, 1, 1, 1])


if __name__ == "__main__":
    unittest.main()
