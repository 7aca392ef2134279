"""The add-on's point, spot, sun and world conversion (addon/model/light_units.py) in plain Python:
no Blender needed (the measurements are tests/blender/test_light_units.py).

run_tests.py puts build/addon/radiosity on sys.path, where model/light_units.py is copied by
the build; it imports only math and numpy.
"""

import math
import sys
import unittest

import numpy as np

from model import light_units

V3, V4, V5 = (3, 4, 1), (4, 5, 15), (5, 0, 1)


class LightUnitsTest(unittest.TestCase):
    def test_bpy_free(self):
        self.assertNotIn("bpy", sys.modules)

    def test_point_intensity(self):
        for version in (V3, V4, V5):
            for radius in (0.0, 0.1, 0.25):
                light = light_units.point_light(version, 100.0, (1.0, 0.5, 0.25), radius)
                np.testing.assert_allclose(light["intensity"],
                                           100.0 / (4 * math.pi ** 2) * np.array([1.0, 0.5, 0.25]))
                self.assertEqual(light["radius"], radius)

    def test_point_settings_of_4x(self):
        base = light_units.point_light(V4, 10.0, (1, 1, 1), 0.0)["intensity"]
        np.testing.assert_allclose(light_units.point_light(V4, 10.0, (1, 1, 1), 0.0, exposure=1.5)["intensity"],
                                   base * 2 ** 1.5)
        np.testing.assert_allclose(light_units.point_light(V4, 10.0, (1, 1, 1), 0.0, normalize=False)["intensity"],
                                   10.0 / math.pi ** 2 * np.ones(3))
        np.testing.assert_allclose(light_units.point_light(V4, 10.0, (1, 1, 1), 0.1, normalize=False)["intensity"],
                                   10.0 * 0.01 / math.pi * np.ones(3))
        # 3.x has neither: its lights have no such settings, so they are ignored
        np.testing.assert_allclose(light_units.point_light(V3, 10.0, (1, 1, 1), 0.0, exposure=1.5)["intensity"], base)

    def test_shapes(self):
        self.assertEqual(light_units.point_light_shape(V3), 'DISK')
        self.assertEqual(light_units.point_light_shape(V3, soft_falloff=False), 'DISK')
        self.assertEqual(light_units.point_light_shape(V4), 'DISK')
        self.assertEqual(light_units.point_light_shape(V5, soft_falloff=False), 'SPHERE')
        intensity = np.array([1.0, 2.0, 3.0])
        np.testing.assert_allclose(light_units.point_light_h(intensity, 0.5, 'DISK', 1.0, 0.5),
                                   intensity * 0.5 / 1.25)
        np.testing.assert_allclose(light_units.point_light_h(intensity, 0.5, 'SPHERE', 1.0, 0.5),
                                   intensity * 0.5)
        h = light_units.point_light_h(intensity, 0.0, 'DISK', np.array([1.0, 2.0]), np.array([1.0, -0.5]))
        np.testing.assert_allclose(h, [intensity, 0 * intensity])

    def test_spot_attenuation(self):
        size, blend = math.radians(60.0), 0.3
        c0 = math.cos(size / 2)
        cos = np.array([1.0, c0 + 0.5 * (1 - c0) * blend, c0 - 1e-6, 0.0])
        np.testing.assert_allclose(light_units.spot_attenuation(V4, cos, size, blend), [1.0, 0.5, 0.0, 0.0])
        np.testing.assert_allclose(light_units.spot_attenuation(V3, cos, size, blend), cos * [1.0, 0.5, 0.0, 0.0])
        np.testing.assert_allclose(light_units.spot_attenuation(V5, cos, size, 0.0), [1.0, 1.0, 0.0, 0.0])
        spot = light_units.spot_light(V5, 100.0, (1, 1, 1), 0.0, size, blend)
        self.assertAlmostEqual(spot["cos_half_angle"], c0)
        self.assertAlmostEqual(spot["cos_blend_width"], (1 - c0) * blend)
        self.assertFalse(spot["cos_factor"])
        self.assertTrue(light_units.spot_light(V3, 100.0, (1, 1, 1), 0.0, size, blend)["cos_factor"])
        np.testing.assert_allclose(spot["intensity"], light_units.point_light(V5, 100.0, (1, 1, 1), 0.0)["intensity"])

    def test_sun(self):
        np.testing.assert_allclose(light_units.sun_light(V4, 3.0, (1, 0.5, 0.25), 0.2)["irradiance"],
                                   3.0 / math.pi * np.array([1, 0.5, 0.25]))
        self.assertAlmostEqual(light_units.sun_light(V3, math.pi, (1, 1, 1), math.radians(90))["irradiance"][0],
                               2 * (math.sqrt(2) - 1))
        self.assertAlmostEqual(light_units.sun_light(V3, math.pi, (1, 1, 1), 0.0)["irradiance"][0], 1.0)
        self.assertAlmostEqual(light_units.sun_light(V5, math.pi, (1, 1, 1), 0.4, normalize=False)["irradiance"][0],
                               math.pi * math.sin(0.2) ** 2)
        self.assertAlmostEqual(light_units.sun_light(V5, math.pi, (1, 1, 1), 0.4, exposure=-1)["irradiance"][0], 0.5)
        self.assertEqual(light_units.sun_light(V5, 1.0, (1, 1, 1), 0.4)["angle"], 0.4)

    def test_world(self):
        np.testing.assert_allclose(light_units.world_radiance((0.8, 0.4, 0.2), 1.5), [1.2, 0.6, 0.3])


if __name__ == "__main__":
    unittest.main()
