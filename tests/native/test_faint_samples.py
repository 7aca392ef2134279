"""Exact visibility where it can show; shadow rays for faint light
(native/core/solve/faint_samples.h).

With exact visibility and the standard or Noticeable oracle, a sample whose
unoccluded light from a link is below `faint_share` of what its side gathered
in the ray pass is shadowed by rays. The perceptual and gradient oracles judge
links by their gradients' shape, which shadow rays do not give: every sample
stays exact with them.
Checked against the same solves with every sample exact (faint_share=0): in a
lit room with a lumpy ball (faces facing each other at every distance) most
occluded samples take rays and the light stays where it was, on the room, the
plate's shadow and the ball; in a room lit only directly (nothing reflects)
no sample's light is faint, so the lamp's shadows stay exact. The energy
correction's 3 x 3 grid (on elements whose samples are inset off a contact
line) takes rays at its faint points as well.
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import native_scene, room_with_blocker  # noqa: E402
from test_unlit_sides import exposure, room_with_ball  # noqa: E402



class FaintSamples(unittest.TestCase):
    def test_faint_samples_take_rays_and_the_light_stays(self):
        scene, ball = room_with_ball()
        for oracle, quality in (("standard", 0.0), ("standard", 0.5), ("noticeable", 0.5)):
            with self.subTest(oracle=oracle, quality=quality):
                exact = rad.solve(scene, oracle=oracle, quality=quality, faint_share=0.0)
                mixed = rad.solve(scene, oracle=oracle, quality=quality)
                self.assertEqual(exact.stats["samples_faint"], 0)
                polygons = {r: r.stats["samples_occluded"] - r.stats["samples_faint"] for r in (exact, mixed)}
                # Most occluded samples' light is faint: their exact polygons go.
                self.assertGreater(mixed.stats["samples_faint"], 0.5 * mixed.stats["samples_occluded"])
                self.assertLess(polygons[mixed], 0.5 * polygons[exact])
                # Refined, some elements have a corner on a contact line
                # (inset samples, the energy correction's exact grid): the
                # grid's points where the link's light is faint take rays.
                self.assertEqual(exact.stats["grid_points_faint"], 0)
                if quality > 0.0:
                    self.assertGreater(mixed.stats["grid_points_faint"], 0)
                for faces, side, delta in ((None, 0, 0.005), (ball, 0, 0.01)):
                    self.assertAlmostEqual(exposure(mixed, faces, side) / exposure(exact, faces, side), 1.0,
                                           delta=delta)
                self.assertTrue(np.isfinite(mixed.radiance).all())

    def test_oracles_that_judge_by_gradients_keep_every_sample_exact(self):
        scene, _ = room_with_ball()
        for oracle in ("perceptual", "gradient"):
            with self.subTest(oracle=oracle):
                r = rad.solve(scene, oracle=oracle, quality=0.3, faint_share=0.5)
                self.assertGreater(r.stats["samples_occluded"], 0)
                self.assertEqual(r.stats["samples_faint"], 0)

    def test_a_floor_lit_only_by_the_lamp_has_no_faint_sample(self):
        # Only the floor reflects: all it gathers is the lamp's light, through
        # links whose shafts the plate crosses, each a large share of it.
        b, parts = room_with_blocker()
        a = b.arrays()
        positions = a["positions"].reshape(-1, 3)
        starts = np.cumsum(a["face_sizes"]) - a["face_sizes"]
        floor = [f for f in parts["room"]
                 if np.all(positions[a["face_vertices"][starts[f]:starts[f] + a["face_sizes"][f]], 2] == 0.0)]
        self.assertEqual(len(floor), 1)
        reflectance = np.zeros_like(a["reflectance"])
        reflectance[floor] = a["reflectance"][floor]
        a["reflectance"] = reflectance
        scene = native_scene(rad, a)
        for oracle in ("standard", "noticeable"):
            with self.subTest(oracle=oracle):
                r = rad.solve(scene, oracle=oracle, quality=0.5)
                self.assertGreater(r.stats["samples_occluded"], 0)
                self.assertEqual(r.stats["samples_faint"], 0)


if __name__ == "__main__":
    unittest.main()
