"""Broken, hostile and extreme input through the Python API (issue 19's
reproducers): every case gives a finite result or a clear ValueError /
MemoryError, never a crash, a NaN or a hang; budgets are kept.
"""

import pathlib
import sys
import time
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, box_field, room_with_blocker  # noqa: E402

ORACLES = ("standard", "perceptual", "gradient")


def open_room(copies=1):
    """A 4 x 4 x 3 room without a ceiling, a downward light, and `copies`
    coincident copies of one floating quad (an import with doubled faces)."""
    b = SceneBuilder()
    b.box((0, 0, 0), (4, 4, 3), rho=0.6, inward=True, skip=(1,))
    b.polygon([(1.7, 1.7, 2.9), (1.7, 2.3, 2.9), (2.3, 2.3, 2.9), (2.3, 1.7, 2.9)], rho=0.0, emission=5.0,
              two_sided=False)
    quads = [b.polygon([(1, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)], rho=0.5) for _ in range(copies)]
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
        n = len(b.positions)
        b.positions.extend(np.array(p, float) for p in [(0, 0, 1), (1, 0, 1), (1, 1e-13, 1), (0, 1, 1.5)])
        b.faces += [[n, n + 1, n + 1, n + 2], [n, n, n], [n, n + 1, n + 2, n + 3, n + 1]]
        for _ in range(3):
            b.reflectance.append(np.full(3, 0.5))
            b.emission.append(np.zeros(3))
            b.two_sided.append(True)
        scene = b.scene(rad)
        skipped = dict(scene.skipped_faces)
        self.assertIn(len(b.faces) - 2, skipped)  # [n, n, n]: coincident corners
        self.assertRegex(skipped[len(b.faces) - 2], "zero area")
        assert_finite(self, rad.solve(scene, quality=0.5))


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
                result = rad.solve(self.builder.scene(rad, scale=scale), quality=0.3)
                assert_finite(self, result)
                self.assertAlmostEqual(np.asarray(result.radiance).sum() / light, 1.0, delta=0.01)
        with self.assertRaisesRegex(ValueError, "coordinates beyond"):
            self.builder.scene(rad, scale=1e31)
        with self.assertRaisesRegex(ValueError, "scenes smaller than"):
            self.builder.scene(rad, scale=1e-7)
        a = self.builder.arrays()
        with self.assertRaisesRegex(ValueError, "too far for its size"):
            rad.Scene(a["positions"] + 1e7, a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"])


class Budgets(unittest.TestCase):
    def assert_on_time(self, seconds, budget):
        # The contract: within 10 % plus one second.
        self.assertLess(seconds, 1.1 * budget + 1.0)

    def test_a_million_bounces_keep_a_two_second_budget(self):
        b, _ = room_with_blocker()
        start = time.monotonic()
        result = rad.solve(b.scene(rad), bounces=10**6, time_budget=2.0, quality=0.3)
        self.assert_on_time(time.monotonic() - start, 2.0)
        self.assertEqual(result.stats["stopped_by"], "time_budget")
        assert_finite(self, result)

    def test_the_budget_holds_while_linking_a_large_scene(self):
        scene = box_field(2000).scene(rad)
        start = time.monotonic()
        result = rad.solve(scene, quality=1.0, time_budget=1.0)
        self.assert_on_time(time.monotonic() - start, 1.0)
        self.assertEqual(result.stats["stopped_by"], "time_budget")
        assert_finite(self, result)

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
