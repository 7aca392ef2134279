"""Energy at the default settings: the furnace and a lit closed room, for every
oracle at qualities 0.3, 0.5 and 0.8 and reflectances up to 0.99.

In a closed room every bit of light is absorbed somewhere: the power the
surfaces absorb must equal what the light emits. White rooms amplify any loss
per bounce by 1 / (1 - rho), so a 0.3 % loss per bounce (what the solver lost
before its transport was balanced, native/README.md) becomes 0.6 % at
rho = 0.5 and 5 % at 0.99, and the furnace (every face emitting and
reflecting alike) was 1.4 % off at 0.9.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from kernels_module import MISSING, kernels  # noqa: E402
from result_geometry import polygon_areas, polygons  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, box_between, native_scene  # noqa: E402
from test_solver import ORACLES, absorbed_power, closed_box  # noqa: E402

QUALITIES = (0.3, 0.5, 0.8)
LAMP_RADIANCE = 5.0


def tolerance(rho):
    return 1e-2 if rho > 0.95 else 1e-3


def lit_room(rho):
    """A closed 4 x 4 x 3 m room, reflectance rho everywhere, lit by a 0.6 m
    square one-sided lamp filling a hole in the ceiling (so nothing hides
    behind it)."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (4, 4, 3), reflectance=rho, inward=True, omit=("top",))
    for x0, x1, y0, y1 in ((0, 4, 0, 1.7), (0, 4, 2.3, 4), (0, 1.7, 1.7, 2.3), (2.3, 4, 1.7, 2.3)):
        b.polygon([(x0, y1, 3), (x1, y1, 3), (x1, y0, 3), (x0, y0, 3)], reflectance=rho)  # facing down
    b.polygon([(1.7, 2.3, 3), (2.3, 2.3, 3), (2.3, 1.7, 3), (1.7, 1.7, 3)], reflectance=rho, emission=LAMP_RADIANCE,
              two_sided=False)
    return b


class FurnaceAtDefaults(unittest.TestCase):
    def test_uniform_radiance_everywhere(self):
        for rho in (0.5, 0.9, 0.99):
            for oracle in ORACLES:
                for quality in QUALITIES:
                    with self.subTest(rho=rho, oracle=oracle, quality=quality):
                        result = rad.solve(closed_box(rho, 0.7).scene(rad), oracle=oracle, quality=quality)
                        error = np.abs(result.radiance / (0.7 / (1 - rho)) - 1).max()
                        print("[furnace] rho %.2f %-10s q %.1f: worst %.1e, %d elements"
                              % (rho, oracle, quality, error, result.stats["elements"]), flush=True)
                        self.assertLess(error, tolerance(rho))


class LitRoomBalance(unittest.TestCase):
    def test_absorbed_equals_emitted(self):
        emitted = math.pi * LAMP_RADIANCE * 0.36
        for rho in (0.5, 0.9, 0.99):
            for oracle in ORACLES:
                for quality in QUALITIES:
                    with self.subTest(rho=rho, oracle=oracle, quality=quality):
                        b = lit_room(rho)
                        result = rad.solve(b.scene(rad), oracle=oracle, quality=quality)
                        ratio = absorbed_power(b, result) / emitted
                        print("[balance] rho %.2f %-10s q %.1f: absorbed / emitted %.5f, %d elements, %d iterations"
                              % (rho, oracle, quality, ratio[0], result.stats["elements"],
                                 result.stats["iterations"]), flush=True)
                        np.testing.assert_allclose(ratio, 1.0, rtol=tolerance(rho))
                        self.assertGreater(result.stats["elements"], 30)  # refined: the balance is tested with refinement

    def test_white_room_converges_in_a_few_dozen_iterations(self):
        # Jacobi alone gains a factor rho per iteration: about 900 iterations
        # at rho = 0.99 (tolerance 1e-6). The tail extrapolation (convergence.h)
        # takes the remaining geometric series at once.
        result = rad.solve(lit_room(0.99).scene(rad), oracle="perceptual", quality=0.3)
        self.assertLess(result.stats["iterations"], 200)
        self.assertLess(result.stats["residual"], 1e-6)


def spot_power(light):
    """Power a spot light sends into its cone (per colour channel), in the
    units absorbed_power measures: pi times its intensity integrated over the
    cone, with the blend's smoothstep and the cosine falloff."""
    c = np.linspace(light["cos_half_angle"], 1.0, 200001)
    t = np.clip((c - light["cos_half_angle"]) / light["blend_width"], 0.0, 1.0)
    cone = c * t * t * (3 - 2 * t)
    return math.pi * 2 * math.pi * light["intensity"][0] * float(np.sum(0.5 * (cone[1:] + cone[:-1]) * np.diff(c)))


def spot_on_a_rotated_box(rho, shift):
    """lights_room's spot and box (scenes/lights_room.py) in a closed room of
    reflectance rho: the box stands turned by 20 degrees, so contact meshing
    cuts the floor around it into quads that are not parallelograms, and how
    it cuts them turns on the last bits of the coordinates (`shift` moves
    every vertex by up to that fraction of the room's diagonal)."""
    b = SceneBuilder()
    add_box(b, (-2, -1.5, 0), (2, 1.5, 2.6), reflectance=rho, inward=True)
    corners, quads = box_between((-0.3, -0.3, 0.0), (0.3, 0.3, 0.6))
    turn = math.radians(20)
    rotation = np.array([[math.cos(turn), -math.sin(turn), 0], [math.sin(turn), math.cos(turn), 0], [0, 0, 1]])
    b.add(corners @ rotation.T + (0.7, 0.4, 0.0), quads.ravel(), np.full(len(quads), 4), rho, 0.0, True)
    a = b.arrays()
    a["positions"] = a["positions"] + np.random.default_rng(7).uniform(-1, 1, a["positions"].shape) * shift * 5.6
    aim = np.array([0.7, 0.4, 0.0]) - (1.7, -1.2, 2.3)
    light = {"type": "spot", "position": (1.7, -1.2, 2.3), "intensity": (3.2, 3.2, 3.2), "radius": 0.05,
             "shape": "disk", "direction": tuple(aim / np.linalg.norm(aim)),
             "cos_half_angle": math.cos(math.radians(22.5)), "blend_width": 0.03, "cosine_falloff": True}
    return a, light


class SplitQuadsKeepTheirArea(unittest.TestCase):
    def test_a_spot_on_a_floor_cut_around_a_turned_box(self):
        # The floor's pieces around the box are quads but not parallelograms:
        # their children differ in area and their interpolants weigh the wide
        # end more (Hierarchy::subdivide, average_weights). Counted as
        # quarters, a piece under the spot's pool lost up to 3.6 % of the
        # spot's direct light in the bookkeeping, depending on how the floor
        # was cut: absorbed / emitted 0.9815 to 0.9967 here, and lights_room's
        # spot came out -2.3 to -3.7 % against Cycles. With the true areas
        # 0.9998 to 1.0031 (7 December 2026).
        for shift in (0.0, 1e-9, 2e-9, 3e-9):
            for oracle in ORACLES:
                with self.subTest(shift=shift, oracle=oracle):
                    a, light = spot_on_a_rotated_box(0.5, shift)
                    result = rad.solve(native_scene(rad, a, lights=[light]), oracle=oracle, quality=0.5)
                    rho = a["reflectance"][result.source_face]
                    absorbed = math.pi * ((1 - rho) * result.irradiance * polygon_areas(result)[:, None]).sum(axis=0)
                    ratio = absorbed / spot_power(light)
                    print("[split quads] shift %.0e %-10s: absorbed / emitted %.4f, %d elements"
                          % (shift, oracle, ratio[0], result.stats["elements"]), flush=True)
                    np.testing.assert_allclose(ratio, 1.0, atol=5e-3)


def sunlit_room_with_window(rho):
    """spot_on_a_rotated_box's room and box with a 1.2 x 1 m window in the left
    wall (lights_room's) and the sun through it, onto the floor's cut pieces."""
    b = SceneBuilder()
    add_box(b, (-2, -1.5, 0), (2, 1.5, 2.6), reflectance=rho, inward=True, omit=("left",))
    for (y0, z0), (y1, z1) in (((-1.5, 0), (1.5, 1)), ((-1.5, 2), (1.5, 2.6)), ((-1.5, 1), (-0.6, 2)),
                               ((0.6, 1), (1.5, 2))):
        b.polygon([(-2, y0, z0), (-2, y1, z0), (-2, y1, z1), (-2, y0, z1)], reflectance=rho)  # facing +x
    corners, quads = box_between((-0.3, -0.3, 0.0), (0.3, 0.3, 0.6))
    turn = math.radians(20)
    rotation = np.array([[math.cos(turn), -math.sin(turn), 0], [math.sin(turn), math.cos(turn), 0], [0, 0, 1]])
    b.add(corners @ rotation.T + (0.7, 0.4, 0.0), quads.ravel(), np.full(len(quads), 4), rho, 0.0, True)
    direction = np.array([0.72, 0.12, -0.68]) / np.linalg.norm([0.72, 0.12, -0.68])
    sun = {"type": "sun", "direction": tuple(direction), "irradiance": (1.0, 1.0, 1.0), "angle": math.radians(1)}
    window = np.array([(-2, -0.6, 1), (-2, 0.6, 1), (-2, 0.6, 2), (-2, -0.6, 2)], dtype=float)  # facing +x
    box = [corners[list(q)] @ rotation.T + (0.7, 0.4, 0.0) for q in quads]
    occluders = np.array([[q[0], q[1], q[2]] for q in box] + [[q[0], q[2], q[3]] for q in box])
    return b, sun, window, occluders


class OpenRoomBalance(unittest.TestCase):
    @unittest.skipIf(kernels is None, MISSING)
    def test_what_the_sun_brings_in_is_absorbed_or_leaves_by_the_window(self):
        # An open room has no closed form, but light is still kept: what the
        # sun brings in through the window (its irradiance times the window's
        # area seen along it) is absorbed inside or leaves by the window. What
        # leaves is the surfaces' light times their form factors to the window
        # (at each output polygon's centre, past the box). Measured 1.0004
        # (standard) and 1.0027 (Noticeable); with the floor's pieces counted
        # as quarters 1.0247 and 1.0251: 2.5 % of the light made.
        for oracle in ("standard", "noticeable"):
            with self.subTest(oracle=oracle):
                b, sun, window, occluders = sunlit_room_with_window(0.5)
                result = rad.solve(native_scene(rad, b.arrays(), lights=[sun]), oracle=oracle, quality=0.8)
                areas = polygon_areas(result)
                inside = result.source_side == 0  # the box's outside, the room's inside
                rho = b.arrays()["reflectance"][result.source_face]
                absorbed = math.pi * ((1 - rho) * result.irradiance * areas[:, None])[inside].sum(axis=0)
                leaving = np.zeros(3)
                for i in np.flatnonzero(inside):
                    corners = result.positions[polygons(result)[i]]
                    normal = np.cross(corners[1:-1] - corners[0], corners[2:] - corners[0]).sum(axis=0)
                    f, _ = kernels.visible_form_factor(corners.mean(axis=0), normal / np.linalg.norm(normal),
                                                       window, occluders)
                    leaving += math.pi * areas[i] * rho[i] * result.irradiance[i] * f
                brought_in = math.pi * 1.2 * np.dot(sun["direction"], (1, 0, 0))
                ratio = (absorbed + leaving) / brought_in
                print("[open room] %-10s: (absorbed %.4f + leaving %.4f) / brought in %.4f = %.4f, %d elements"
                      % (oracle, absorbed[0], leaving[0], brought_in, ratio[0], result.stats["elements"]), flush=True)
                np.testing.assert_allclose(ratio, 1.0, atol=3e-3)


if __name__ == "__main__":
    unittest.main()
