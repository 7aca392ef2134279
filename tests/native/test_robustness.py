"""Broken, hostile and extreme input through the Python API (issue 19's
reproducers): every case gives a finite result or a clear ValueError /
MemoryError, never a crash, a NaN or a hang; budgets are kept.
"""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, box_field, room_with_blocker, scaled_scene  # noqa: E402
from work_clock import WorkClock  # noqa: E402

from test_solver import ORACLES  # noqa: E402


def open_room(copies=1):
    """A 4 x 4 x 3 room without a ceiling, a downward light, and `copies`
    coincident copies of one floating quad (an import with doubled faces)."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.6, inward=True, omit=("top",))
    b.polygon([(1.7, 1.7, 2.9), (1.7, 2.3, 2.9), (2.3, 2.3, 2.9), (2.3, 1.7, 2.9)], reflectance=0.0, emission=5.0,
              two_sided=False)
    quads = [b.polygon([(1, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)], reflectance=0.5) for _ in range(copies)]
    return b, quads


def assert_finite(test, result):
    for name in ("positions", "radiance", "vertex_irradiance", "irradiance"):
        values = np.asarray(getattr(result, name))
        test.assertTrue(np.isfinite(values).all(), f"{name} has {np.count_nonzero(~np.isfinite(values))} non-finite")


def floor_irradiance(b, result, face=0):
    """Area-weighted mean gathered H of one input face (its lit side)."""
    sizes = np.asarray(result.face_sizes)
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    positions, corners = np.asarray(result.positions), np.asarray(result.face_vertices)
    total, area = 0.0, 0.0
    for p in np.flatnonzero(np.asarray(result.source_face) == face):
        ring = positions[corners[starts[p]:starts[p] + sizes[p]]]
        a = 0.5 * np.linalg.norm(sum(np.cross(ring[k] - ring[0], ring[k + 1] - ring[0])
                                     for k in range(1, len(ring) - 1)))
        total += a * float(np.mean(result.irradiance[p]))
        area += a
    return total / area


class DoubledFaces(unittest.TestCase):
    def test_sixteen_coincident_quads_solve_like_one_and_are_named(self):
        single, _ = open_room(1)
        reference = rad.solve(single.scene(rad), quality=0.3)
        doubled, quads = open_room(16)
        scene = doubled.scene(rad)
        named = {face for pair in scene.coincident_faces for face in pair}
        self.assertEqual(named, set(quads), "every copy is named as coinciding")
        for oracle in ORACLES:
            for visibility in ("exact", "sampled"):
                with self.subTest(oracle=oracle, visibility=visibility):
                    result = rad.solve(scene, oracle=oracle, quality=0.0 if oracle != "standard" else 0.3,
                                       visibility=visibility, threads=1 + len(oracle) % 2)
                    assert_finite(self, result)
        result = rad.solve(scene, quality=0.3)
        assert_finite(self, result)
        # The floor under the quads gets the light of one quad's shadow, not 16 times anything.
        self.assertAlmostEqual(floor_irradiance(doubled, result) / floor_irradiance(single, reference), 1.0, delta=0.01)


class BrokenPolygons(unittest.TestCase):
    def test_self_intersecting_repeated_index_emitters_give_finite_light(self):
        # Six random polygons of 3 to 8 corners over 30 random points, all
        # emitting: bow-ties, repeated corners, non-planar, mutually piercing
        # (contact meshing cuts them into hundreds of pieces).
        for seed in range(4):
            rng = np.random.default_rng(seed)
            positions = rng.uniform(0, 1, (30, 3))
            sizes = rng.integers(3, 9, 6)
            corners = rng.integers(0, 30, int(sizes.sum()))
            with self.subTest(seed=seed):
                scene = rad.Scene(positions, corners, sizes, np.full((6, 3), 0.5), np.full((6, 3), 1e3))
                result = rad.solve(scene, oracle=ORACLES[seed % 3], quality=0.2 if seed == 3 else 0.0)
                assert_finite(self, result)
                self.assertGreater(float(np.asarray(result.radiance).max()), 0.0)

    def test_repeated_corners_and_slivers_are_skipped_or_solved_with_a_reason(self):
        b, _ = open_room(0)
        b.add([(0, 0, 1), (1, 0, 1), (1, 1e-13, 1), (0, 1, 1.5)], [0, 1, 1, 2, 0, 0, 0, 0, 1, 2, 3, 1], [4, 3, 5],
              0.5, 0.0, True)
        scene = b.scene(rad)
        skipped = {note["face"]: note["kind"] for note in scene.skipped_faces}
        self.assertEqual(skipped.get(b.face_count - 2), "coincident_corners")  # [n, n, n]
        assert_finite(self, rad.solve(scene, quality=0.5))


    def test_a_non_planar_quad_is_split_as_blender_splits_it_and_its_bend_is_named(self):
        # A quad with one corner lifted by 0.2.
        b, _ = open_room(0)
        face = b.polygon([(1, 1, 1), (2, 1, 1), (2, 2, 1.2), (1, 2, 1)], reflectance=0.5)
        scene = b.scene(rad)
        self.assertEqual([(n["face"], n["kind"]) for n in scene.repaired_faces], [(face, "not_planar")])
        note = scene.repaired_faces[0]
        # The bend: the corners' largest distance from the plane through their
        # centroid normal to the area vector, over the diameter.
        q = np.array([(1, 1, 1), (2, 1, 1), (2, 2, 1.2), (1, 2, 1)], float)
        normal = np.cross(q[2] - q[0], q[3] - q[1])
        normal /= np.linalg.norm(normal)
        expected = np.max(np.abs((q - q.mean(axis=0)) @ normal)) / np.linalg.norm(q[2] - q[0])
        self.assertAlmostEqual(note["bend"], expected, delta=1e-6)
        self.assertEqual(note["triangles"], 2)
        # Blender splits along the 0-2 diagonal: both triangles hold corners 0 and 2.
        pieces = [p for p in scene.patches if p["sides"][0] and p["sides"][0][0] == face]
        self.assertEqual(len(pieces), 2)
        for piece in pieces:
            corners = {tuple(np.round(c, 9)) for c in piece["corners"]}
            self.assertTrue({(1.0, 1.0, 1.0), (2.0, 2.0, 1.2)} <= corners, corners)
        self.assertEqual(rad.solve(scene, quality=0.3).stats["repaired_faces"], 1)

    def test_repeated_corners_are_removed_and_named(self):
        b, _ = open_room(0)
        face = b.face_count
        b.add([(1, 1, 1), (2, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)], [0, 1, 2, 3, 4, 0],  # a repeated index too
              [6], 0.5, 0.0, True)
        scene = b.scene(rad)
        self.assertEqual(scene.repaired_faces, [{"face": face, "kind": "repeated_corners", "corners": 2}])
        self.assertEqual(len([p for p in scene.patches if p["sides"][0] and p["sides"][0][0] == face]), 1,
                         "solved as the planar quad it is")

    def test_a_bow_tie_is_skipped_with_its_reason_and_the_rest_solves(self):
        b, _ = open_room(0)
        face = b.polygon([(1, 1, 1), (2, 2, 1), (2, 1, 1), (1, 2, 1)], reflectance=0.5)
        scene = b.scene(rad)
        self.assertEqual(scene.skipped_faces, [{"face": face, "kind": "crosses_itself"}])
        result = rad.solve(scene, quality=0.3)
        assert_finite(self, result)
        self.assertNotIn(face, set(np.asarray(result.source_face)))

    def test_a_face_too_small_for_floating_point_is_skipped(self):
        # Fuzzing (generator seed 594270769): a 3e-13 quad 1 m from a wall of
        # a 20 m scene, under a white world, made the wall NaN.
        b = SceneBuilder()
        b.polygon([(-7.05, -10.6, -6.46), (-7.05, 7.09, -6.46), (-7.05, 7.09, 7.25), (-7.05, -10.6, 7.25)],
                  reflectance=0.8, emission=2.0)
        corner = np.array([-6.051289913666132, -2.401285793458587, 1.8345027129815215])
        offsets = [(0, 0, 0), (5.17e-13, 2.64e-13, 5.76e-13), (5.2e-13, 2.86e-13, 6.02e-13), (4.66e-13, 5.1e-13, 8.15e-13)]
        tiny = b.polygon([corner + o for o in offsets], reflectance=0.6, emission=1.0)
        b.polygon([(3.59, 4.06, 6.12), (3.59, 10.8, 6.12), (3.59, 10.8, 4.1), (3.59, 4.06, 4.1)], reflectance=0.2, emission=1.0)
        a = b.arrays()
        scene = rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                          a["two_sided"], world=np.array([40.7, 50.2, 6.9]))
        (note,) = [n for n in scene.skipped_faces if n["face"] == tiny]
        self.assertEqual(note["kind"], "too_small")
        across = max(np.linalg.norm(np.subtract(p, q)) for p in offsets for q in offsets)
        self.assertAlmostEqual(note["size"], across, delta=1e-3 * across)
        self.assertAlmostEqual(note["scene_size"], np.linalg.norm(np.ptp(a["positions"], axis=0)), places=6)
        for oracle in ORACLES:
            assert_finite(self, rad.solve(scene, oracle=oracle, quality=0.0, leaf_links="all"))

    def test_a_bent_quad_and_its_reversed_copy_converge(self):
        # Fuzzing (atheris): one non-planar quad twice, the second reversed,
        # under a white world: the four triangles close a tetrahedron 2e6
        # across whose inside reflects 0.9. The radiances overflowed (an
        # extrapolation fed a mode that alternates in sign).
        positions = np.array([[443137.2549019567, 443137.2549019608, 443137.2549019608],
                              [-685718.5091357678, 289062.499996362, -994869.1125027839],
                              [-999992.2577189296, 898039.2156845483, -992187.5771353545],
                              [-294117.686804384, 312500.4000030458, 999969.3636859774]])
        scene = rad.Scene(positions, np.array([3, 0, 2, 1, 1, 2, 0, 3]), np.array([4, 4]), np.full((2, 3), 0.9),
                          np.zeros((2, 3)), world=np.array([2.9, 10.0, 9.0]))
        self.assertEqual(len(scene.repaired_faces), 2)
        for options in (dict(quality=0.21, leaf_links="all", max_elements=161), dict(quality=0.0),
                        dict(quality=0.21, visibility="sampled")):
            with self.subTest(**options):
                result = rad.solve(scene, **options)
                assert_finite(self, result)
                # Inside and out, nothing exceeds what a closed surface of
                # reflectance 0.9 lit by the world can reach: 10 / (1 - 0.9).
                self.assertLess(float(np.max(result.radiance)), 100.0)
                self.assertLess(result.stats["residual"], 1e-3)


class OutOfRange(unittest.TestCase):
    def setUp(self):
        self.builder, _ = room_with_blocker()
        self.scene = self.builder.scene(rad)

    def test_counts_out_of_range_are_value_errors(self):
        for kwargs in (dict(threads=2**31 - 1), dict(threads=2**64), dict(threads=0), dict(threads=1.5),
                       dict(rays=2**40), dict(bounces=-1), dict(bounces=2**63), dict(max_elements=2**70),
                       dict(memory_limit=-5), dict(time_budget=float("nan")), dict(quality=float("nan"))):
            with self.subTest(**{k: repr(v) for k, v in kwargs.items()}):
                with self.assertRaises(ValueError):
                    rad.solve(self.scene, **kwargs)

    def test_a_face_that_casts_no_shadow_must_not_reflect(self):
        # Fuzz seed 1482: coincident copies of a face, some casting no shadow
        # and reflecting, exchanged light at distance 0 (NaN).
        a = self.builder.arrays()
        occludes = np.ones(len(a["face_sizes"]), bool)
        occludes[2] = False
        with self.assertRaisesRegex(ValueError, "face 2 casts no shadow .* must have reflectance 0"):
            rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                      occludes=occludes)

    def test_counts_take_numpy_integers(self):
        result = rad.solve(self.scene, quality=0.0, threads=np.int64(2), rays=np.int32(4), max_elements=np.uint64(10**6))
        assert_finite(self, result)

    def test_face_sizes_that_wrap_around_are_refused(self):
        a = self.builder.arrays()
        sizes = a["face_sizes"].copy()
        # Adds up to the right count only modulo 2^64.
        sizes = np.concatenate([sizes, np.full(4, 2**62, np.int64)])
        n = len(sizes)
        with self.assertRaisesRegex(ValueError, "face_sizes adds up to more than"):
            rad.Scene(a["positions"], a["face_vertices"], sizes, np.full((n, 3), 0.5), np.ones((n, 3)))

    def test_radiance_beyond_the_range_is_refused_and_within_it_stays_finite(self):
        a = self.builder.arrays()
        with self.assertRaisesRegex(ValueError, "emission of face 6 is 5e\\+300; it must lie in \\[0, 1e\\+30\\]"):
            rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"] * 1e300)
        bright = rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"],
                           a["emission"] / 5 * 1e30)
        result = rad.solve(bright, quality=0.3)
        assert_finite(self, result)
        with self.assertRaisesRegex(ValueError, "colour \\(intensity\\) must lie in"):
            rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                      lights=[dict(type="point", position=(2, 2, 2), intensity=(1e300, 1, 1))])
        with self.assertRaisesRegex(ValueError, "world's radiance"):
            rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                      world=(1e31, 0, 0))

    def test_scenes_at_extreme_scales_solve_the_same_or_are_refused(self):
        reference = rad.solve(self.scene, quality=0.3)
        light = np.asarray(reference.radiance).sum()
        for scale in (1e-5, 1e25):
            with self.subTest(scale=scale):
                result = rad.solve(scaled_scene(rad, self.builder, scale=scale), quality=0.3)
                assert_finite(self, result)
                self.assertAlmostEqual(np.asarray(result.radiance).sum() / light, 1.0, delta=0.01)
        with self.assertRaisesRegex(ValueError, "coordinates beyond"):
            scaled_scene(rad, self.builder, scale=1e31)
        with self.assertRaisesRegex(ValueError, "scenes smaller than"):
            scaled_scene(rad, self.builder, scale=1e-7)
        a = self.builder.arrays()
        with self.assertRaisesRegex(ValueError, "too far for its size"):
            rad.Scene(a["positions"] + 1e7, a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"])


class Budgets(unittest.TestCase):
    # The time budget is read on a fake clock that moves with the solve's own
    # progress reports (work_clock.py), so where it stops is the same on any
    # machine at any load; bench/time_budget.py measures it in wall time.

    def test_a_million_bounces_keep_their_budget(self):
        b, _ = room_with_blocker()
        clock = WorkClock(budget=2.0, step=0.1, phases=("refining", "gathering"))
        result = rad.solve(b.scene(rad), bounces=10**6, time_budget=clock.budget, quality=0.3, clock=clock,
                           progress=clock.progress)
        self.assertEqual(result.stats["stopped_by"], "time_budget")
        self.assertGreater(len(clock.reports), 2.0 / 0.1 - 1)  # it worked until the budget was spent
        self.assertLessEqual(len(clock.late), 1, clock.late)  # then finished only the iteration in flight
        self.assertLess(result.stats["seconds"], clock.budget + 1.5 * clock.step)
        assert_finite(self, result)

    def test_the_budget_holds_while_linking_a_large_scene(self):
        # Linking reports as its walk goes (30 reports up to 5 %, then each block
        # of links up to 10 %): the budget runs out ten reports in.
        scene = box_field(2000).scene(rad)
        clock = WorkClock(budget=1.0, step=0.1, phases=("linking",))
        result = rad.solve(scene, quality=1.0, time_budget=clock.budget, clock=clock, progress=clock.progress)
        self.assertEqual(result.stats["stopped_by"], "time_budget")
        self.assertEqual(result.stats["passes"], 0)
        self.assertLessEqual(len(clock.late), 1, clock.late)
        self.assertLess(max(fraction for _, fraction in clock.reports + clock.late), 0.05)  # the walk cut short
        assert_finite(self, result)

    def test_a_failing_clock_stops_the_solve_with_its_error(self):
        def broken():
            raise ZeroDivisionError("no time")
        b, _ = room_with_blocker()
        with self.assertRaisesRegex(ZeroDivisionError, "no time"):
            rad.solve(b.scene(rad), quality=0.3, time_budget=5.0, clock=broken)
        with self.assertRaisesRegex(ValueError, "clock must be callable"):
            rad.solve(b.scene(rad), quality=0.3, clock=3.0)

    def test_the_memory_limit_stops_refinement(self):
        b, _ = room_with_blocker()
        scene = b.scene(rad)
        free = rad.solve(scene, quality=0.8)
        limit = free.stats["peak_bytes"] // 3
        capped = rad.solve(scene, quality=0.8, memory_limit=limit)
        self.assertEqual(capped.stats["stopped_by"], "memory")
        self.assertLess(capped.stats["elements"], free.stats["elements"])
        assert_finite(self, capped)

    def test_a_scene_that_cannot_fit_is_refused_before_any_work(self):
        b, _ = room_with_blocker()
        with self.assertRaisesRegex(MemoryError, "needs about .* GB before any refinement"):
            rad.solve(b.scene(rad), memory_limit=1000)


if __name__ == "__main__":
    unittest.main()
