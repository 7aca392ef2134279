"""Sides no light reaches are left out of linking (RayPass::unlit,
native/core/solve/ray_pass.h).

Blender's faces are two-sided, so a closed object has an inside, and a
dense one's inside faces each other at every distance: four fifths of the
links of bench/tessellated_room.py. The ray pass finds the sides light cannot
reach (it spreads from what emits, what a light, an emitter or the sky lights
directly, and openings, along the rays each side traced) and linking leaves
them out. Nothing that light reaches may be left out: a closed object solves
as it does with its inside sides missing altogether, and an opening or a light
inside it keeps every side.
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from large_scenes import _icosphere  # noqa: E402
from synthetic_scenes import room_with_blocker  # noqa: E402
from test_solver import polygon_areas  # noqa: E402

ORACLES = ("standard", "perceptual", "gradient", "noticeable")
# The room's outer sides (six faces, the ceiling cut in five pieces around the
# lamp 1 cm under it): under no sky nothing lights them.
ROOM_OUTSIDE = 10
LUMINANCE = np.array([0.2126, 0.7152, 0.0722])


def room_with_ball(two_sided=True, opening=0, light_inside=False, sky=0.0, lamp=5.0):
    """room_with_blocker's lit room with a lumpy icosphere (320 triangles,
    radius 0.5, dents that face each other) floating beside the plate; its
    `opening` triangles nearest the ceiling light left out; with
    `light_inside`, a point light at its centre; under a uniform `sky`; the
    ceiling light's emission `lamp` (a number or a colour)."""
    b, parts = room_with_blocker(light=lamp)
    v, f = _icosphere(2)
    ripple = 1 + 0.3 * np.sin(5 * v[:, 0]) * np.sin(5 * v[:, 1]) * np.sin(5 * v[:, 2] + 1)
    centre = np.array([1.0, 1.0, 1.2])
    ball = v * ripple[:, None] * 0.5 + centre
    if opening:
        height = ball[f].mean(axis=1)[:, 2]
        f = f[np.argsort(height)[:-opening]]
    first = b.face_count
    b.add(ball, f.ravel(), np.full(len(f), 3), 0.6, 0.0, two_sided)
    lights = [{"type": "point", "position": centre, "intensity": np.full(3, 5.0)}] if light_inside else []
    a = b.arrays()
    scene = rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"],
                      a["emission"], a["two_sided"], occludes=a["occludes"], lights=lights, world=np.full(3, sky))
    return scene, list(range(first, b.face_count))


def exposure(result, faces=None, side=None):
    """Area-weighted mean luminance of the polygons' radiance (of `faces` on `side`)."""
    keep = np.ones(len(result.face_sizes), dtype=bool)
    if faces is not None:
        keep &= np.isin(result.source_face, faces)
    if side is not None:
        keep &= result.source_side == side
    corner_radiance = result.radiance[result.face_vertices] @ LUMINANCE
    polygon = np.add.reduceat(corner_radiance, np.cumsum(result.face_sizes) - result.face_sizes)
    polygon = polygon / result.face_sizes
    areas = polygon_areas(result)[keep]
    return float((polygon[keep] * areas).sum() / areas.sum())


class ClosedObjects(unittest.TestCase):
    def test_a_closed_object_solves_as_if_it_had_no_inside(self):
        # Every oracle unrefined, the default refined.
        for oracle, quality in [(o, 0.0) for o in ORACLES] + [("noticeable", 0.5)]:
            with self.subTest(oracle=oracle, quality=quality):
                both_scene, ball = room_with_ball(two_sided=True)
                one_scene, _ = room_with_ball(two_sided=False)
                both = rad.solve(both_scene, oracle=oracle, quality=quality)
                one = rad.solve(one_scene, oracle=oracle, quality=quality)
                # Its 320 inside sides, and the outside of the room's walls.
                self.assertEqual(both.stats["unlit_sides"], 320 + ROOM_OUTSIDE)
                self.assertEqual(one.stats["unlit_sides"], ROOM_OUTSIDE)
                # The same links and elements (the inside's top level stays,
                # unlinked and unrefined). Not to the last one: the ray pass
                # draws its rays by element number, and the inside's elements
                # shift the numbers, so the energy balance's share of rays that
                # escape is another draw (its light within 3e-4).
                for count in ("links", "cluster_links", "light_links", "elements"):
                    extra = 320 if count == "elements" else 0
                    expected = one.stats[count] + extra
                    self.assertLessEqual(abs(both.stats[count] - expected), 1e-3 * expected, count)
                self.assertAlmostEqual(exposure(both, side=0) / exposure(one, side=0), 1.0, delta=3e-4)
                self.assertAlmostEqual(exposure(both, ball, 0) / exposure(one, ball, 0), 1.0, delta=3e-4)
                inside = np.isin(both.source_face, ball) & (both.source_side == 1)
                self.assertFalse(inside.any())  # shown as the inside of a one-sided object: absent


    def test_under_a_sky_the_room_outside_is_lit_and_the_inside_is_not(self):
        scene, _ = room_with_ball(sky=0.5)
        self.assertEqual(rad.solve(scene, quality=0.0).stats["unlit_sides"], 320)


class LightGetsIn(unittest.TestCase):
    def test_through_an_opening_light_reaches_the_whole_inside(self):
        for oracle in ("standard", "noticeable"):
            with self.subTest(oracle=oracle):
                scene, ball = room_with_ball(opening=4)
                result = rad.solve(scene, oracle=oracle, quality=0.5)
                self.assertEqual(result.stats["unlit_sides"], ROOM_OUTSIDE)
                inside = exposure(result, ball, 1)
                self.assertGreater(inside, 0.0)
                # Through four of 320 triangles: a glimmer of the outside's light.
                self.assertLess(inside, 0.2 * exposure(result, ball, 0))

    def test_a_light_inside_lights_the_inside(self):
        scene, ball = room_with_ball(light_inside=True)
        result = rad.solve(scene, oracle="noticeable", quality=0.5)
        self.assertEqual(result.stats["unlit_sides"], ROOM_OUTSIDE)
        self.assertGreater(exposure(result, ball, 1), exposure(result, ball, 0))


if __name__ == "__main__":
    unittest.main()
