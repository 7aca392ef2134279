"""Relighting without relinking (SolveReuse, native/include/radiosity/solve.h).

A solve passed a SolveReuse keeps its elements and links; the next solve of
the same geometry with the same options, whose lighting alone changed,
starts from them: it evaluates no link it already has, converges, and
refines only where the new radiances ask. Checked against solves from
nothing: a light twice as strong (an exact scaling, so the same refinement)
gives the same mesh and radiances to the solve's tolerance; a wall's new
colour gives the same light per face to within the discretisation (the two
refine along different histories); every other change solves from nothing
and says why.
"""

import pathlib
import sys
import threading
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, native_scene, room_with_blocker  # noqa: E402
from test_solver import ORACLES, polygon_areas, reflected_power  # noqa: E402

QUALITY = 0.6


def scene(builder, emission_scale=1.0, reflectance=None, positions=None, lights=None):
    a = builder.arrays()
    return rad.Scene(a["positions"] if positions is None else positions, a["face_vertices"], a["face_sizes"],
                     a["reflectance"] if reflectance is None else reflectance, a["emission"] * emission_scale,
                     a["two_sided"], lights=lights)


def face_light(result, faces):
    """Area-weighted mean of the gathered light H over each input face."""
    areas = polygon_areas(result)
    h = np.asarray(result.irradiance).mean(axis=1)
    source = np.asarray(result.source_face)
    return np.array([(areas * h)[source == f].sum() / areas[source == f].sum() for f in range(faces)])


class RelightTest(unittest.TestCase):
    def setUp(self):
        self.builder, self.parts = room_with_blocker()

    def solve(self, oracle, reuse=None, **changes):
        return rad.solve(scene(self.builder, **changes), oracle=oracle, quality=QUALITY, reuse=reuse)

    def test_a_stronger_light_reuses_everything_and_equals_a_solve_from_nothing(self):
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                reuse = rad.SolveReuse()
                first = self.solve(oracle, reuse)
                self.assertFalse(first.stats["reused"])
                self.assertTrue(reuse.holds)
                self.assertGreater(reuse.memory_bytes, 0)
                relit = self.solve(oracle, reuse, emission_scale=2.0)
                fresh = self.solve(oracle, emission_scale=2.0)
                self.assertTrue(relit.stats["reused"], relit.stats["reuse_refusal"])
                self.assertEqual(relit.stats["reuse_refusal"], "")
                # No link evaluated again, no new element: the thresholds are
                # relative to the scene's brightness.
                self.assertEqual(relit.stats["samples_clear"] + relit.stats["samples_occluded"], 0)
                self.assertEqual(relit.stats["seconds_linking"], 0.0)
                np.testing.assert_array_equal(relit.positions, fresh.positions)
                np.testing.assert_array_equal(relit.face_vertices, fresh.face_vertices)
                scale = float(np.max(fresh.radiance))
                np.testing.assert_allclose(relit.radiance, fresh.radiance, rtol=0, atol=1e-5 * scale)
                np.testing.assert_allclose(relit.radiance, 2.0 * first.radiance, rtol=0, atol=1e-5 * scale)

    def test_a_solve_whose_cluster_links_were_all_refined_relights_exactly(self):
        # A 2 m room with a box on its floor: the first pass links the box's
        # sides and the far walls as clusters, refinement replaces every one
        # of them with links between faces. The light the cluster links
        # gathered before must go with them: left over, it was counted beside
        # the face links' (0.15 % of the cube scene's light), and a relight
        # kept it at the old brightness (2.7e-4 of the brightest off).
        def box_room(emission):
            b = SceneBuilder()
            add_box(b, (0, 0, 0), (2, 2, 2), reflectance=0.7, inward=True)
            b.polygon([(0.75, 0.75, 1.99), (0.75, 1.25, 1.99), (1.25, 1.25, 1.99), (1.25, 0.75, 1.99)], 0.0,
                      emission=emission, two_sided=False)
            add_box(b, (0.6, 0.6, 0), (1.1, 1.1, 0.5), reflectance=0.7)
            return native_scene(rad, b.arrays())

        for oracle in ("standard", "noticeable"):
            with self.subTest(oracle=oracle):
                coarse = rad.solve(box_room(10.0), oracle=oracle, quality=0.2)
                self.assertGreater(coarse.stats["cluster_links"], 0)
                reuse = rad.SolveReuse()
                first = rad.solve(box_room(10.0), oracle=oracle, quality=0.5, reuse=reuse)
                self.assertEqual(first.stats["cluster_links"], 0)
                relit = rad.solve(box_room(20.0), oracle=oracle, quality=0.5, reuse=reuse)
                self.assertTrue(relit.stats["reused"], relit.stats["reuse_refusal"])
                scale = float(np.max(relit.radiance))
                np.testing.assert_allclose(relit.radiance, 2.0 * first.radiance, rtol=0, atol=1e-5 * scale)

    def test_a_new_wall_colour_gives_the_light_of_a_solve_from_nothing(self):
        refl = self.builder.arrays()["reflectance"].copy()
        refl[self.parts["room"][2]] = (0.8, 0.2, 0.2)
        faces = self.builder.face_count
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                reuse = rad.SolveReuse()
                self.solve(oracle, reuse)
                relit = self.solve(oracle, reuse, reflectance=refl)
                fresh = self.solve(oracle, reflectance=refl)
                self.assertTrue(relit.stats["reused"], relit.stats["reuse_refusal"])
                # The red wall's light on every face, and the light the room holds.
                lit, expected = face_light(relit, faces), face_light(fresh, faces)
                np.testing.assert_allclose(lit, expected, rtol=0.02)
                self.assertAlmostEqual(reflected_power(relit) / reflected_power(fresh), 1.0, delta=0.005)

    def test_a_white_light_turned_red_relights_every_colour(self):
        # The relight starts from the old solution scaled to the new light's
        # luminance, so the luminance hardly changes while every colour does:
        # convergence measured on luminance alone stopped after three
        # iterations with the room's green a third of its red, not a fifth.
        reuse = rad.SolveReuse()
        for colour in ((5.0, 5.0, 5.0), (5.0, 1.0, 1.0)):
            result = rad.solve(native_scene(rad, room_with_blocker(light=colour)[0].arrays()), oracle="standard",
                               quality=QUALITY, reuse=reuse)
        self.assertTrue(result.stats["reused"], result.stats["reuse_refusal"])
        lit = result.radiance[:, 0] > 1e-3 * float(np.max(result.radiance[:, 0]))
        np.testing.assert_allclose(result.radiance[lit, 1] / result.radiance[lit, 0], 0.2, rtol=1e-3)

    def test_light_colours_relight_and_a_light_turned_on_does_not(self):
        lamp = {"type": "point", "position": (1.0, 1.0, 2.0), "intensity": (3.0, 3.0, 3.0)}
        warm = dict(lamp, intensity=(4.0, 2.5, 1.0))
        reuse = rad.SolveReuse()
        self.solve("perceptual", reuse, lights=[lamp])
        relit = self.solve("perceptual", reuse, lights=[warm])
        fresh = self.solve("perceptual", lights=[warm])
        self.assertTrue(relit.stats["reused"], relit.stats["reuse_refusal"])
        faces = self.builder.face_count
        np.testing.assert_allclose(face_light(relit, faces), face_light(fresh, faces), rtol=0.02)
        # A light with no intensity is no light: turning one on adds a light.
        off = dict(lamp, position=(3.0, 3.0, 2.0), intensity=(0.0, 0.0, 0.0))
        still = self.solve("perceptual", reuse, lights=[warm, off])
        self.assertTrue(still.stats["reused"], still.stats["reuse_refusal"])
        again = self.solve("perceptual", reuse, lights=[warm, dict(off, intensity=(1.0, 1.0, 1.0))])
        self.assertFalse(again.stats["reused"])
        self.assertEqual(again.stats["reuse_refusal"], "lights_added_or_removed")

    def test_what_the_kept_links_cannot_carry_solves_from_nothing(self):
        a = self.builder.arrays()
        moved = a["positions"].copy()
        moved[-1] += 0.01
        light = self.parts["light"]
        lit_light_back = a["reflectance"].copy()
        lit_light_back[light] = (0.5, 0.5, 0.5)  # the lamp reflected nothing: nothing was linked to it
        cases = [
            ("geometry_changed", dict(positions=moved), {}),
            ("now_reflects", dict(reflectance=lit_light_back), {}),
            ("oracle_changed", {}, dict(oracle="standard")),
            ("quality_changed", {}, dict(quality=QUALITY + 0.1)),
            ("visibility_changed", {}, dict(visibility="sampled")),
        ]
        for why, scene_changes, option_changes in cases:
            with self.subTest(why):
                reuse = rad.SolveReuse()
                self.solve("perceptual", reuse)
                options = dict(oracle="perceptual", quality=QUALITY)
                options.update(option_changes)
                result = rad.solve(scene(self.builder, **scene_changes), reuse=reuse, **options)
                self.assertFalse(result.stats["reused"])
                self.assertEqual(result.stats["reuse_refusal"], why)
                self.assertTrue(reuse.holds)  # the new solve is kept instead

    def test_a_surface_that_starts_emitting_solves_from_nothing(self):
        a = self.builder.arrays()
        emission = a["emission"].copy()
        emission[self.parts["blocker"][0]] = (1.0, 1.0, 1.0)
        reuse = rad.SolveReuse()
        self.solve("perceptual", reuse)
        result = rad.solve(rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"],
                                     emission, a["two_sided"]), oracle="perceptual", quality=QUALITY, reuse=reuse)
        self.assertFalse(result.stats["reused"])
        self.assertEqual(result.stats["reuse_refusal"], "now_emits")

    def test_a_cancelled_solve_is_not_kept(self):
        reuse = rad.SolveReuse()
        token = rad.CancelToken()
        token.cancel()
        self.solve("perceptual", reuse)
        self.assertTrue(reuse.holds)
        result = rad.solve(scene(self.builder, emission_scale=3.0), oracle="perceptual", quality=QUALITY,
                           reuse=reuse, cancel=token)
        self.assertTrue(result.stats["cancelled"])
        self.assertFalse(reuse.holds)
        reuse.clear()  # clearing nothing is harmless

    def test_a_failed_relight_is_not_kept(self):
        reuse = rad.SolveReuse()
        self.solve("perceptual", reuse)

        def fail(report):
            raise RuntimeError("the caller's progress callback failed")

        with self.assertRaisesRegex(RuntimeError, "progress callback failed"):
            rad.solve(scene(self.builder, emission_scale=2.0), oracle="perceptual", quality=QUALITY, reuse=reuse,
                      progress=fail)
        self.assertFalse(reuse.holds)

    def test_one_solve_at_a_time_per_reuse(self):
        reuse = rad.SolveReuse()
        errors = []

        def progress(report):
            # Inside the first solve, which holds the reuse: a second must refuse at
            # once; what it holds reads as of before this solve (nothing yet).
            if not errors:
                errors.append((reuse.holds, reuse.memory_bytes))
                try:
                    rad.solve(scene(self.builder), quality=0.0, reuse=reuse)
                    errors.append(None)
                except ValueError as err:
                    errors.append(str(err))
                try:
                    reuse.clear()
                    errors.append(None)
                except ValueError as err:
                    errors.append(str(err))

        done = []
        worker = threading.Thread(target=lambda: done.append(
            rad.solve(scene(self.builder), quality=0.3, reuse=reuse, progress=progress)))
        worker.start()
        worker.join()
        self.assertEqual(errors, [(False, 0), "this SolveReuse is in use by another solve",
                                  "this SolveReuse is in use by a solve"])
        self.assertTrue(done and reuse.holds)
        self.assertGreater(reuse.memory_bytes, 0)

    def test_reuse_must_be_a_solve_reuse(self):
        with self.assertRaisesRegex(ValueError, "reuse must be a SolveReuse"):
            rad.solve(scene(self.builder), quality=0.0, reuse=object())


if __name__ == "__main__":
    unittest.main()
