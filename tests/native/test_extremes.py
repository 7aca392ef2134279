"""Input at the extremes (issue 34), each with the accuracy it keeps: black
and almost white rooms, emitters from 1e-6 to 1e6, a millimetre box in a
kilometre hall, slivers a million times longer than wide. A room 10 km from
the origin and the same scenes in other units are in test_units.py; input
beyond the solver's range is refused in test_robustness.py.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, scaled_scene  # noqa: E402
from test_energy import LAMP_RADIANCE, lit_room  # noqa: E402
from test_robustness import assert_finite  # noqa: E402
from test_solver import ORACLES, absorbed_power, polygon_areas  # noqa: E402


def side_irradiance(result, face, side=0):
    """Area-weighted mean gathered H over one side of an input face."""
    on = (result.source_face == face) & (result.source_side == side)
    areas = polygon_areas(result)[on]
    return (result.irradiance[on, 0] * areas).sum() / areas.sum()


def lamp_over(builder, lo, hi, z, radiance=10.0):
    builder.polygon([(lo, lo, z), (lo, hi, z), (hi, hi, z), (hi, lo, z)], reflectance=0.0, emission=radiance,
                    two_sided=False)


class Reflectance(unittest.TestCase):
    def test_a_black_room_shows_its_emission_and_nothing_else(self):
        b = lit_room(0.0)
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                result = rad.solve(b.scene(rad), oracle=oracle)
                assert_finite(self, result)
                emission = b.arrays()["emission"][result.source_face]
                lamp = emission[:, 0] > 0
                self.assertTrue(lamp.any() and (~lamp).any())
                # Per vertex: the lamp's polygons show L_e, the rest 0.
                starts = np.cumsum(result.face_sizes) - result.face_sizes
                for polygon in np.flatnonzero(~lamp)[:50]:
                    corners = result.face_vertices[starts[polygon]:starts[polygon] + result.face_sizes[polygon]]
                    np.testing.assert_array_equal(np.asarray(result.radiance)[corners], 0.0)

    def test_an_almost_white_room_keeps_its_light(self):
        # rho = 0.999: a light bounces about a thousand times before it is
        # absorbed; what the walls absorb still equals what the lamp emits.
        # Measured: 0.9990 to 0.9991, every oracle (0.990 to 0.999 before the
        # sending side counted the receiving correction, energy_balance.cpp).
        emitted = math.pi * LAMP_RADIANCE * 0.36
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                b = lit_room(0.999)
                result = rad.solve(b.scene(rad), oracle=oracle, quality=0.3)
                assert_finite(self, result)
                ratio = absorbed_power(b, result)[0] / emitted
                print("[white room] rho 0.999 %-10s: absorbed / emitted %.5f, %d elements, %d iterations"
                      % (oracle, ratio, result.stats["elements"], result.stats["iterations"]), flush=True)
                self.assertAlmostEqual(ratio, 1.0, delta=3e-3)


class Emission(unittest.TestCase):
    def test_emitters_from_a_millionth_to_a_million_light_alike(self):
        # The oracles' thresholds are relative to the scene's mean radiance:
        # the same mesh, and radiance in proportion to the emission.
        b = lit_room(0.8)
        for oracle in ORACLES:
            reference = rad.solve(b.scene(rad), oracle=oracle)
            for factor in (1e-6, 1e6):
                with self.subTest(oracle=oracle, factor=factor):
                    result = rad.solve(scaled_scene(rad, b, emission_scale=factor), oracle=oracle)
                    assert_finite(self, result)
                    self.assertEqual(result.stats["elements"], reference.stats["elements"])
                    expected = np.asarray(reference.radiance)
                    np.testing.assert_allclose(np.asarray(result.radiance) / factor, expected, rtol=0,
                                               atol=1e-6 * expected.max())


class Sizes(unittest.TestCase):
    def test_a_millimetre_box_in_a_kilometre_hall_is_lit_like_a_metre_box(self):
        # Six orders of magnitude between the hall (1 km across, 100 m high,
        # a 200 m light under its roof) and the box on its floor: the box's
        # top sees the light as a box a thousand times larger does.
        tops = {}
        for oracle in ORACLES:
            for size in (1e-3, 1.0):
                b = SceneBuilder()
                add_box(b, (-500, -500, 0), (500, 500, 100), reflectance=0.5, inward=True)
                lamp_over(b, -100, 100, 99)
                box = add_box(b, (-size / 2, -size / 2, 0), (size / 2, size / 2, size), reflectance=0.5)
                result = rad.solve(b.scene(rad), oracle=oracle)
                assert_finite(self, result)
                tops[size] = side_irradiance(result, box[1])
            with self.subTest(oracle=oracle):
                print("[hall] %-10s: H on the top of a 1 mm box %.4f, of a 1 m box %.4f"
                      % (oracle, tops[1e-3], tops[1.0]), flush=True)
                self.assertAlmostEqual(tops[1e-3] / tops[1.0], 1.0, delta=0.02)

    def test_slivers_a_million_times_longer_than_wide_are_lit_like_strips(self):
        # A quad and a triangle 1 m long and 1 um wide, 1 mm over the floor
        # under the light, against the same shapes 5 cm wide.
        for oracle in ORACLES:
            light = {}
            for width in (1e-6, 0.05):
                b = SceneBuilder()
                add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.5, inward=True)
                lamp_over(b, 1.7, 2.3, 2.99)
                quad = b.polygon([(1.5, 2, 1e-3), (2.5, 2, 1e-3), (2.5, 2 + width, 1e-3), (1.5, 2 + width, 1e-3)])
                triangle = b.polygon([(1.5, 2.5, 1e-3), (2.5, 2.5, 1e-3), (2.0, 2.5 + width, 1e-3)])
                result = rad.solve(b.scene(rad), oracle=oracle)
                assert_finite(self, result)
                light[width] = np.array([side_irradiance(result, quad), side_irradiance(result, triangle)])
            with self.subTest(oracle=oracle):
                ratio = light[1e-6] / light[0.05]
                print("[slivers] %-10s: H on slivers over H on 5 cm strips: quad %.4f, triangle %.4f"
                      % (oracle, ratio[0], ratio[1]), flush=True)
                np.testing.assert_allclose(ratio, 1.0, atol=0.01)


if __name__ == "__main__":
    unittest.main()
