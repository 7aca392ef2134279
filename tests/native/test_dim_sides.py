"""Sides too dim to link gather by the ray pass's rays (native/core/solve/dim_sides.h).

The inside of a closed object lit only through a gap faces itself at every
distance, and its pairs were most of the links of a dense scene for a
hundredth of the room's light. A side no ray of the first look brought direct
light to, whose light there is below `dim_share` of the mean, is left out of
linking: it gathers what its rays met, and the linked sides gather its light
through their rays that met it, both from the solution as it stands. Checked
against the same solves with every lit side linked (dim_share=0): the light
in the room and inside the object, with the inside's share small and with
every side lit only indirectly gathering by rays (dim_share=1), where light
the dim sides did not send on would be missed; and a relight of a new light
colour, which the rays must carry inside.
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from test_unlit_sides import ROOM_OUTSIDE, exposure, room_with_ball  # noqa: E402

INSIDE = 1  # the ball's faces point out: side 1 is its inside
# Through its gap of four triangles the ball's inside gathers 2 to 6 % of the
# room's mean light: below the default 2 % it would be linked.
SHARE = 0.1


def links(result):
    return result.stats["links"] + result.stats["cluster_links"]


class DimInside(unittest.TestCase):
    def test_the_inside_of_a_ball_with_a_gap_gathers_by_rays(self):
        scene, ball = room_with_ball(opening=4)
        # The inside's light, every side linked and refined far.
        reference = exposure(rad.solve(scene, oracle="standard", quality=0.8, dim_share=0.0), ball, INSIDE)
        for oracle, quality in (("standard", 0.0), ("standard", 0.5), ("noticeable", 0.5)):
            with self.subTest(oracle=oracle, quality=quality):
                by_rays = rad.solve(scene, oracle=oracle, quality=quality, dim_share=SHARE)
                linked = rad.solve(scene, oracle=oracle, quality=quality, dim_share=0.0)
                self.assertEqual(linked.stats["dim_sides"], 0)
                self.assertEqual(by_rays.stats["unlit_sides"], ROOM_OUTSIDE)
                # Most of the 316 inside sides: those the lamp shines on
                # through the gap, or that see it, stay linked.
                self.assertGreater(by_rays.stats["dim_sides"], 150)
                self.assertLess(by_rays.stats["dim_sides"], 316)
                self.assertLess(links(by_rays), 0.8 * links(linked))
                # Shown, finite, with the linked solve's light in the room (to
                # 0.2 %) and the reference's inside to 15 %: its rays see the
                # room's top-level elements at their mean (measured 5 to 13 %
                # under; the linked solve at quality 0 is 31 % over).
                inside = np.isin(by_rays.source_face, ball) & (by_rays.source_side == INSIDE)
                self.assertTrue(inside.any())
                self.assertTrue(np.isfinite(by_rays.radiance).all())
                self.assertGreaterEqual(float(np.min(by_rays.radiance)), 0.0)
                self.assertAlmostEqual(exposure(by_rays, side=0) / exposure(linked, side=0), 1.0, delta=2e-3)
                self.assertAlmostEqual(exposure(by_rays, ball, INSIDE) / reference, 1.0, delta=0.15)

    def test_light_the_dim_sides_reflect_goes_on(self):
        # Every side no ray brought direct light to gathers by rays: the
        # ceiling, the walls' tops, the plate's top, the room behind the ball.
        # Their reflected light is a large share of the room's: lost if the
        # linked sides did not gather it through their rays, made twice if
        # the energy balance still asked the links for it.
        scene, ball = room_with_ball(opening=4)
        everything = rad.solve(scene, oracle="standard", quality=0.3, dim_share=1.0)
        linked = rad.solve(scene, oracle="standard", quality=0.3, dim_share=0.0)
        self.assertGreater(everything.stats["dim_sides"], 400)
        self.assertAlmostEqual(exposure(everything, side=0) / exposure(linked, side=0), 1.0, delta=0.02)
        self.assertAlmostEqual(exposure(everything, ball, INSIDE) / exposure(linked, ball, INSIDE), 1.0,
                               delta=0.1)

    def test_a_new_light_colour_reaches_the_dim_inside(self):
        # The dim sides read the solution as it stands: a relight needs no new rays.
        reuse = rad.SolveReuse()
        white, ball = room_with_ball(opening=4, lamp=(5.0, 5.0, 5.0))
        first = rad.solve(white, oracle="standard", quality=0.3, reuse=reuse, dim_share=SHARE)
        self.assertGreater(first.stats["dim_sides"], 0)
        red, _ = room_with_ball(opening=4, lamp=(5.0, 1.0, 1.0))
        relit = rad.solve(red, oracle="standard", quality=0.3, reuse=reuse, dim_share=SHARE)
        self.assertTrue(relit.stats["reused"], relit.stats["reuse_refusal"])
        fresh = rad.solve(red, oracle="standard", quality=0.3, dim_share=SHARE)
        inside = np.isin(relit.source_face, ball) & (relit.source_side == INSIDE)
        corners = relit.face_vertices[np.repeat(inside, relit.face_sizes)]
        colour = relit.radiance[corners].mean(axis=0)
        self.assertAlmostEqual(colour[1] / colour[0], 0.2, delta=0.01)  # red, as the lamp is
        self.assertAlmostEqual(exposure(relit, ball, INSIDE) / exposure(fresh, ball, INSIDE), 1.0, delta=0.02)


if __name__ == "__main__":
    unittest.main()
