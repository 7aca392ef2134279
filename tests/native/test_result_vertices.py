"""What the bake's per-vertex data relies on in the solver's output mesh
(native/core/hierarchy/output_mesh.cpp), checked on solved synthetic scenes:

- a result vertex is shared only by polygons of the same input face and side
  (addon/model/surface_uv.py interpolates UVs per corner anyway, so a vertex with one
  value per face side is what the "Radiosity Light" and UV data assume);
- vertex_irradiance is the H behind the radiance: radiance = emission + rho x H
  at every vertex, with the rho and emission of its polygons' face.
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import room_with_blocker  # noqa: E402


class ResultVerticesTest(unittest.TestCase):
    def test_vertices_shared_within_one_face_side_and_radiance_from_h(self):
        b, _ = room_with_blocker()
        a = b.arrays()
        # A textured-like floor: a quad split by the blocker's shadow, and a triangle.
        for oracle in ("standard", "perceptual"):
            with self.subTest(oracle=oracle):
                result = rad.solve(b.scene(rad), oracle=oracle, quality=0.5)
                sizes = np.asarray(result.face_sizes)
                fv = np.asarray(result.face_vertices)
                face = np.repeat(np.asarray(result.source_face), sizes)
                side = np.repeat(np.asarray(result.source_side), sizes)
                key = face * 2 + side
                first = np.full(len(result.positions), -1)
                first[fv[::-1]] = key[::-1]
                self.assertTrue(np.all(first[fv] == key), "a vertex shared across faces or sides")
                h = np.asarray(result.vertex_irradiance, dtype=np.float64)
                radiance = np.asarray(result.radiance, dtype=np.float64)
                self.assertEqual(h.shape, radiance.shape)
                self.assertTrue(np.all(h >= 0))
                rho = a["reflectance"][face]
                emission = a["emission"][face]
                expected = emission + rho * h[fv]
                np.testing.assert_allclose(radiance[fv], expected, rtol=1e-5, atol=1e-6 * radiance.max())


if __name__ == "__main__":
    unittest.main()
