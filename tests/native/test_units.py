"""The same scene in any unit and anywhere (issue 34): a room modelled in
millimetres or kilometres, or 10 km from the origin, must solve to the same
light. The solver works in its own frame (scene.h, SolverFrame): positions
centred on the bounding box, scaled to a diameter of 1 and rounded to a grid,
so its tolerances, its decisions and the ray tracer's float32 geometry are
the same for all of them.

Radiance has no unit of length: scaling a scene leaves the emission of its
surfaces as it is, and scales a point or spot light's intensity by the square
of the factor (H = I cos / d^2).
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, room_with_blocker  # noqa: E402
from test_hanging_lamp import hanging_lamp_room  # noqa: E402
from result_geometry import lit_mean_irradiance  # noqa: E402
from test_solver import ORACLES  # noqa: E402

SPOT = dict(type="spot", direction=(0.3, 0.2, -1.0), intensity=(4.0, 3.0, 2.0), radius=0.05,
            cos_half_angle=0.8, blend_width=0.1)
POINT = dict(type="point", intensity=(2.0, 2.0, 2.0), radius=0.02)
SUN = dict(type="sun", direction=(0.4, 0.3, -1.0), irradiance=(3.0, 3.0, 3.0), angle=0.01)
SKY = (0.5, 0.6, 0.9)


# The solver rounds its frame's positions to a grid of 2^-32 of the scene's
# diameter (scene.h, SolverFrame), so a scene written in another unit or
# place is the same numbers inside it: the same mesh, and the same light to
# rounding (measured: every case within 3e-14). Before the grid, the last
# bits of the coordinates tipped refinement's decisions: up to 16 % more or
# fewer elements, 1.3e-3 of the light in the room lit by a point and a spot.
RADIANCE_TOLERANCE = 1e-10


def open_room():
    """The room without its ceiling, and the plate: lit from outside."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.6, inward=True, omit=("top",))
    b.polygon([(1.4, 1.4, 1.0), (2.6, 1.4, 1.0), (2.6, 2.6, 1.0), (1.4, 2.6, 1.0)], reflectance=0.5)
    return b


def scenes():
    """A room with a ceiling light and a plate's shadow, the hanging lamp (its
    cover 1 cm under the ceiling) in a white room, the room lit by a point
    and a spot light instead, and by the sun and the sky without its ceiling."""
    blocker = room_with_blocker()[0]
    lamp = hanging_lamp_room(0.8, 0.01)
    lights = [dict(POINT, position=(1.0, 3.0, 2.5)), dict(SPOT, position=(3.0, 1.0, 2.8))]
    return dict(blocker=(blocker, []), lamp=(lamp, []), point_and_spot=(room_with_blocker(light=0.0)[0], lights),
                sun_and_sky=(open_room(), [SUN]))


def moved(builder, lights, scale=1.0, offset=(0.0, 0.0, 0.0)):
    a = builder.arrays()
    offset = np.asarray(offset, float)
    placed = []
    for light in lights:
        if light["type"] != "sun":  # a sun's irradiance has no length in it
            light = dict(light, position=tuple(np.asarray(light["position"]) * scale + offset))
            light["intensity"] = tuple(np.asarray(light["intensity"]) * scale**2)
            light["radius"] *= scale
        placed.append(light)
    sky = SKY if any(light["type"] == "sun" for light in lights) else None
    return rad.Scene(a["positions"] * scale + offset, a["face_vertices"], a["face_sizes"], a["reflectance"],
                     a["emission"], a["two_sided"], lights=placed, world=sky)


class UnitsAndPlaces(unittest.TestCase):
    def solve_pairs(self, **placement):
        for name, (builder, lights) in scenes().items():
            for oracle in ORACLES:
                reference = rad.solve(moved(builder, lights), oracle=oracle)
                result = rad.solve(moved(builder, lights, **placement), oracle=oracle)
                yield name, oracle, reference, result

    def test_millimetres_and_kilometres_give_the_same_mesh_and_light(self):
        for scale in (1e-3, 1e3):
            for name, oracle, reference, result in self.solve_pairs(scale=scale):
                with self.subTest(scale=scale, scene=name, oracle=oracle):
                    change = lit_mean_irradiance(result) / lit_mean_irradiance(reference) - 1
                    print("[units] x%g %-14s %-10s: %d / %d elements, mean radiance %+.1e"
                          % (scale, name, oracle, result.stats["elements"], reference.stats["elements"],
                             np.abs(change).max()), flush=True)
                    np.testing.assert_allclose(change, 0.0, atol=RADIANCE_TOLERANCE)
                    self.assertEqual(result.stats["elements"], reference.stats["elements"])

    def test_a_room_10_km_from_the_origin_solves_as_at_the_origin(self):
        # In float32 a coordinate of 10 km rounds to a millimetre: the lamp's
        # cover 1 cm under the ceiling lost 0.12 % of the room's light there
        # before the solver worked in its own frame.
        offset = (1e4, -1e4, 5e3)
        for name, oracle, reference, result in self.solve_pairs(offset=offset):
            with self.subTest(scene=name, oracle=oracle):
                change = lit_mean_irradiance(result) / lit_mean_irradiance(reference) - 1
                print("[units] +10 km %-14s %-10s: %d / %d elements, mean radiance %+.1e"
                      % (name, oracle, result.stats["elements"], reference.stats["elements"],
                         np.abs(change).max()), flush=True)
                np.testing.assert_allclose(change, 0.0, atol=RADIANCE_TOLERANCE)
                self.assertEqual(result.stats["elements"], reference.stats["elements"])


if __name__ == "__main__":
    unittest.main()
