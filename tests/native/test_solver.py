"""The hierarchical radiosity solver through its Python API: physics (furnace,
energy balance, closed-form exchange), refinement where shadows are, invariance,
crack-free output, validation, cancellation and the ends of the quality range.
"""

import json
import math
import os
import pathlib
import sys
import threading
import time
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from kernels_module import MISSING, kernels  # noqa: E402
from result_geometry import polygon_areas, polygons  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, box_field, room_with_blocker, scaled_scene  # noqa: E402

# Every oracle by the solver's name (its one table, native/core/solve/solve_options.cpp).
ORACLES = tuple(json.loads(rad.DEFAULTS_JSON)["oracles"])


def reflected_power(result):
    """Area-weighted sum of what the surfaces gathered (irradiance, before any
    clamp of the radiance): the light a solution holds."""
    return float((polygon_areas(result) * np.asarray(result.irradiance).mean(axis=1)).sum())


def parallel_squares_form_factor(a, c):
    """Closed form between directly opposed parallel a x a squares at distance c."""
    x = y = a / c
    return 2 / (math.pi * x * y) * (
        math.log(math.sqrt((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)))
        + x * math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))
        + y * math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
        - x * math.atan(x) - y * math.atan(y))


def closed_box(rho, emission):
    """The furnace: the inside of a closed box. One-sided, so the unlit outside
    (which emits too, and would be shown at L_e) is not part of the output."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (1, 1.3, 0.8), reflectance=rho, emission=emission, inward=True, two_sided=False)
    return b


class Furnace(unittest.TestCase):
    """Every face of a closed box emits L_e and reflects rho: L = L_e / (1 - rho).

    With every link on leaves (leaf_links="all"), every sample's form factors
    sum to 1 at any refinement. Pushing interpolated values down instead
    (leaf_links="none", textbook HR) is off by about 10 % next to the box's
    edges; the default hands only near-field links down and scales what the
    far ones push to each sample's closure (energy_balance.h; test_energy.py).
    """

    def test_uniform_radiance_everywhere(self):
        for rho in (0.0, 0.5, 0.9, 0.99):
            for oracle in ORACLES:
                with self.subTest(rho=rho, oracle=oracle):
                    result = rad.solve(closed_box(rho, 0.7).scene(rad), oracle=oracle, quality=0.0)
                    np.testing.assert_allclose(result.radiance, 0.7 / (1 - rho), rtol=1e-3)
                    self.assertLess(result.stats["residual"], 1e-6)

    def test_refined_box(self):
        for rho in (0.5, 0.9, 0.99):
            for oracle in ORACLES:
                with self.subTest(rho=rho, oracle=oracle):
                    # A budget keeps the high-albedo cases (~900 iterations) quick.
                    result = rad.solve(closed_box(rho, 0.7).scene(rad), oracle=oracle, quality=0.5,
                                       max_elements=1500, leaf_links="all")
                    self.assertGreater(result.stats["elements"], 12)  # refined
                    np.testing.assert_allclose(result.radiance, 0.7 / (1 - rho), rtol=1e-3)

    def test_handing_down_fewer_links_trades_accuracy(self):
        errors = {}
        for mode in ("all", "near", "none"):
            result = rad.solve(closed_box(0.5, 0.7).scene(rad), oracle="standard", quality=0.5, leaf_links=mode)
            errors[mode] = np.abs(result.radiance / 1.4 - 1).max()
        self.assertLess(errors["all"], 1e-5)
        self.assertLess(errors["near"], 0.02)
        self.assertGreater(errors["none"], 0.05)


def framed_light_box(rho):
    """A 2 x 1.5 x 1 box open at the top, a light filling a hole in its y = 0
    wall (no gap behind it), a black one-sided window across the opening that
    absorbs what escapes."""
    b = SceneBuilder()
    # The top (walls[1]): the black one-sided window.
    wall, window = np.broadcast_to(rho, 3), np.full(3, 1e-9)
    walls = add_box(b, (0, 0, 0), (2, 1.5, 1), reflectance=[wall, window, wall, wall, wall], inward=True,
                    omit=("front",), two_sided=[True, False, True, True, True])
    for x0, x1, z0, z1 in ((0, 2, 0, 0.3), (0, 2, 0.7, 1), (0, 0.5, 0.3, 0.7), (1.5, 2, 0.3, 0.7)):
        b.polygon([(x0, 0, z0), (x0, 0, z1), (x1, 0, z1), (x1, 0, z0)], reflectance=rho)
    b.polygon([(0.5, 0, 0.3), (0.5, 0, 0.7), (1.5, 0, 0.7), (1.5, 0, 0.3)], reflectance=1e-9, emission=(4, 3, 2),
              two_sided=False)
    return b, walls[1]


def floating_light_box(rho, gap):
    """The same open box with a whole y = 0 wall, the light `gap` in front of
    it: the light hides part of that wall from the rest of the box."""
    b = SceneBuilder()
    wall, window = np.broadcast_to(rho, 3), np.full(3, 1e-9)
    add_box(b, (0, 0, 0), (2, 1.5, 1), reflectance=[wall, window, wall, wall, wall, wall], inward=True,
            two_sided=[True, False, True, True, True, True])  # the top: the black window
    b.polygon([(0.5, gap, 0.3), (0.5, gap, 0.7), (1.5, gap, 0.7), (1.5, gap, 0.3)], reflectance=1e-9,
              emission=(4, 3, 2), two_sided=False)
    return b


LIGHT_POWER = math.pi * np.array([4, 3, 2]) * 0.4


def box_triangles(lo, hi):
    """The triangles of an axis-aligned box without its bottom, for the visibility API."""
    b = SceneBuilder()
    add_box(b, lo, hi, omit=("bottom",))
    a = b.arrays()
    quads = a["positions"][a["face_vertices"].reshape(-1, 4)]
    return np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])


def absorbed_power(builder, result, faces=None):
    rho = builder.arrays()["reflectance"][result.source_face]
    absorbed = math.pi * ((1 - rho) * result.irradiance * polygon_areas(result)[:, None])
    return absorbed.sum(axis=0) if faces is None else absorbed[np.isin(result.source_face, faces)].sum(axis=0)


class EnergyBalance(unittest.TestCase):
    def test_direct_light_is_absorbed_exactly(self):
        # Black walls: only the light's own links carry energy. Each link's
        # samples are corrected to the exact patch form factor, so however
        # coarse the elements, what arrives is what the light emits. A light
        # floating in front of a wall leaves the samples of the walls it meets
        # behind its plane dark; the others carry the whole correction.
        for b in (framed_light_box(1e-9)[0], floating_light_box(1e-9, 1e-3), floating_light_box(1e-9, 0.3)):
            for quality in (0.0, 0.5):
                result = rad.solve(b.scene(rad), oracle="standard", quality=quality)
                np.testing.assert_allclose(absorbed_power(b, result), LIGHT_POWER, rtol=1e-6)

    @unittest.skipIf(kernels is None, MISSING)
    def test_a_receiver_whose_brightest_sample_is_hidden_keeps_its_light(self):
        # Unrefined, a floor sees a ceiling light from its corners, and its
        # centre sample sits under a box. Shifting the samples to the exact
        # unoccluded exchange took more than the visible corners carry: the
        # floor went to zero (black in the render of a room of boxes). Scaled
        # instead, it keeps the samples' visible share of the exact exchange.
        # A large floor under a small light: the centre sample carries most of
        # the samples' average, far more than the exact exchange.
        def floor_gathers(with_box):
            b = SceneBuilder()
            floor = b.polygon([(0, 0, 0), (20, 0, 0), (20, 20, 0), (0, 20, 0)], reflectance=0.5, two_sided=False)
            b.polygon(light, reflectance=0.0, emission=10.0, two_sided=False)
            if with_box:
                add_box(b, *box, reflectance=1e-9, omit=("bottom",))
            result = rad.solve(b.scene(rad), oracle="standard", quality=0.0)
            on_floor = result.source_face == floor
            return (result.irradiance[on_floor, 0] * polygon_areas(result)[on_floor]).sum() / 400.0

        light = [(9.5, 9.5, 2), (9.5, 10.5, 2), (10.5, 10.5, 2), (10.5, 9.5, 2)]
        # Raised 2 cm: a box standing on the floor would split it (contact.h).
        box = ((9.8, 9.8, 0.02), (10.2, 10.2, 0.3))
        up = np.array([0, 0, 1.0])
        centre = np.array([10.0, 10.0, 1e-6])
        hidden, _ = kernels.visible_form_factor(centre, up, np.array(light), box_triangles(*box))
        self.assertEqual(hidden, 0.0)
        corners = sum(kernels.form_factor(np.array([x, y, 1e-6]), up, np.array(light))
                      for x in (1e-5, 20 - 1e-5) for y in (1e-5, 20 - 1e-5))
        # Interpolant weights: 5/36 per corner, 4/9 for the centre.
        visible_share = (5 / 36) * corners / ((5 / 36) * corners + (4 / 9) * kernels.form_factor(centre, up, np.array(light)))
        open_floor = floor_gathers(False)  # 10 x the exact patch form factor
        self.assertGreater(open_floor, 0.0)
        np.testing.assert_allclose(floor_gathers(True), visible_share * open_floor, rtol=1e-4)

    def test_open_box_emitted_equals_absorbed_plus_escaped(self):
        # Every part of a coarse emitter sends what it reflects (the energy
        # balance of the transport, energy_balance.h), whichever links are
        # handed down: before it, the default "near" lost 1 % of the
        # interreflected light (1.3 % before links kept their emitter shape).
        b, window = framed_light_box((0.7, 0.5, 0.3))
        for mode, rtol in (("all", 1e-3), ("near", 1e-3)):
            with self.subTest(leaf_links=mode):
                result = rad.solve(b.scene(rad), oracle="standard", quality=0.6, leaf_links=mode)
                escaped = absorbed_power(b, result, [window])
                walls = absorbed_power(b, result) - escaped
                np.testing.assert_allclose(walls + escaped, LIGHT_POWER, rtol=rtol)
                self.assertTrue(np.all(escaped > 0.05 * LIGHT_POWER), "the opening lets light out")
                self.assertTrue(np.all(walls > 0.2 * LIGHT_POWER), "the walls absorb a good part")

    def test_light_hiding_a_wall_loses_what_its_shadow_samples_miss(self):
        # Where the light hides part of a wall, what the wall gathers is the
        # visible form factor at five samples, interpolated: not the exact
        # visible area-to-area exchange, so energy is conserved only as the
        # shadow's outline is refined (native/README.md, known limits).
        b = floating_light_box((0.7, 0.5, 0.3), 0.3)
        error = {}
        for quality in (0.0, 0.6):
            result = rad.solve(b.scene(rad), oracle="standard", quality=quality, leaf_links="all")
            error[quality] = np.abs(absorbed_power(b, result) / LIGHT_POWER - 1).max()
        self.assertLess(error[0.6], 0.02)
        # Refinement takes off at least a third. It took off half while each
        # wall's closure came from its links alone; from the ray pass (issue
        # 34), the wall behind the lamp, which sees the lamp's black back, sends
        # more: -1.55 % at quality 0.6 where -1.16 % before, -2.4 % unrefined
        # where -2.6 %. Light meeting the back of a one-sided face is lost in
        # both, so which is nearer the truth is not known yet.
        self.assertLess(error[0.6], 0.67 * error[0.0])


class EmitterSides(unittest.TestCase):
    def test_both_sides_of_a_two_sided_black_lamp_are_shown_emitting(self):
        # A lamp that reflects nothing receives no links, yet both its sides
        # emit: the output must show both (a camera above a pendant lamp sees
        # its back), at its emitted radiance.
        b = SceneBuilder()
        add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.6, inward=True)
        lamp = b.polygon([(1.5, 1.5, 2), (2.5, 1.5, 2), (2.5, 2.5, 2), (1.5, 2.5, 2)], reflectance=0.0,
                         emission=(5, 4, 3), two_sided=True)
        result = rad.solve(b.scene(rad), oracle="standard", quality=0.2)
        polygons_of_lamp = result.source_face == lamp
        self.assertEqual(set(result.source_side[polygons_of_lamp].tolist()), {0, 1})
        vertices = np.unique(np.concatenate([poly for poly, keep in zip(polygons(result), polygons_of_lamp) if keep]))
        np.testing.assert_allclose(result.radiance[vertices], np.tile([5, 4, 3], (len(vertices), 1)), rtol=1e-6)


class Clustering(unittest.TestCase):
    """Far clusters of faces that face each other share one link (cluster_links.h)."""

    def test_cluster_links_replace_pairs_and_agree_with_them(self):
        b = box_field(300)
        clustered = rad.solve(b.scene(rad), oracle="standard", quality=0.0, cluster_separation=2.0)
        pairs = rad.solve(b.scene(rad), oracle="standard", quality=0.0, cluster_separation=float("inf"))
        self.assertGreater(clustered.stats["cluster_links"], 100)
        self.assertEqual(pairs.stats["cluster_links"], 0)
        self.assertLess(clustered.stats["links"], 0.8 * pairs.stats["links"])
        # Unrefined, both give the same mesh; the radiance agrees closely (at
        # quality 0 clusters link from twice their radii, both ends clusters:
        # 0.8 % on average, where sides linked one by one were 0.5 %).
        np.testing.assert_array_equal(clustered.face_vertices, pairs.face_vertices)
        self.assertLess(np.abs(clustered.radiance - pairs.radiance).mean() / pairs.radiance.mean(), 1e-2)
        np.testing.assert_allclose(clustered.radiance, pairs.radiance, rtol=0.05, atol=0.02 * pairs.radiance.max())
        # The room is closed: what the cluster links carry is absorbed like the rest.
        np.testing.assert_allclose(absorbed_power(b, clustered), absorbed_power(b, pairs), rtol=3e-3)

    def test_same_result_for_one_and_two_threads(self):
        b = box_field(300)
        one = rad.solve(b.scene(rad), oracle="standard", quality=0.2, cluster_separation=2.0, threads=1)
        two = rad.solve(b.scene(rad), oracle="standard", quality=0.2, cluster_separation=2.0, threads=2)
        self.assertGreater(one.stats["cluster_links"], 0)
        self.assertEqual(one.stats["cluster_links"], two.stats["cluster_links"])
        np.testing.assert_array_equal(one.radiance, two.radiance)

    def test_separation_must_exceed_one(self):
        b, _ = room_with_blocker()
        for bad in (1.0, 0.5, -2.0, float("nan")):
            with self.assertRaisesRegex(ValueError, "cluster_separation"):
                rad.solve(b.scene(rad), cluster_separation=bad)


class TwoFacingSquares(unittest.TestCase):
    def test_gathered_radiance_matches_closed_form(self):
        for distance in (0.5, 1.0, 3.0):
            b = SceneBuilder()
            b.polygon([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], reflectance=0.5)  # faces +z
            b.polygon([(0, 0, distance), (0, 1, distance), (1, 1, distance), (1, 0, distance)],
                      reflectance=0.0, emission=2.0, two_sided=False)  # faces -z
            result = rad.solve(b.scene(rad), oracle="standard", quality=0.8)
            receiver = result.source_face == 0
            mean_h = (result.irradiance[receiver] * polygon_areas(result)[receiver, None]).sum(axis=0)
            expected = 2.0 * parallel_squares_form_factor(1.0, distance)
            np.testing.assert_allclose(mean_h, expected, rtol=1e-3)


def visibility_class(points, normal, light, occluders):
    """0 umbra, 1 penumbra, 2 lit, from the exact visible fraction of the light."""
    classes = []
    for p in points:
        unoccluded = kernels.form_factor(p, normal, light)
        visible, _ = kernels.visible_form_factor(p, normal, light, occluders)
        f = visible / unoccluded
        classes.append(0 if f < 1e-3 else 2 if f > 1 - 1e-3 else 1)
    return np.array(classes)


class ShadowRefinement(unittest.TestCase):
    @unittest.skipIf(kernels is None, MISSING)  # the floor's visibility classes
    def test_each_oracle_refines_most_at_the_shadow_boundary(self):
        b, ids = room_with_blocker()
        a = b.arrays()
        offsets = np.concatenate([[0], np.cumsum(a["face_sizes"])])
        face = lambda f: a["positions"][a["face_vertices"][offsets[f]:offsets[f + 1]]]
        light = face(ids["light"])
        occluders = np.array([face(f)[list(t)] for f in ids["blocker"] for t in ((0, 1, 2), (0, 2, 3))])
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                result = rad.solve(b.scene(rad), oracle=oracle, quality=0.5)
                floor = np.nonzero(result.source_face == ids["room"][0])[0]
                polys = polygons(result)
                centroids = np.array([result.positions[polys[i]].mean(axis=0) for i in floor])
                # Away from the room's walls, where contact with the walls refines too.
                inner = np.all((centroids[:, :2] > 0.6) & (centroids[:, :2] < 3.4), axis=1)
                centroids, cells = centroids[inner], floor[inner]
                classes = visibility_class(centroids + [0, 0, 1e-6], np.array([0, 0, 1.0]), light, occluders)
                areas = polygon_areas(result)[cells]
                density = [np.sum(classes == k) / areas[classes == k].sum() for k in range(3)]
                self.assertGreater(density[1], 1.5 * density[2], f"penumbra vs lit {density}")
                self.assertGreater(density[1], 1.5 * density[0], f"penumbra vs umbra {density}")


class Invariance(unittest.TestCase):
    def test_scale_and_brightness(self):
        # The light hangs 30 cm under the ceiling: 1 cm under it, the ceiling
        # behind it is its own patch (contact.h), seen from the room only at
        # grazing angles through the gap, where which side of an edge a ray
        # passes is decided by rounding, which scaling changes.
        b, _ = room_with_blocker(gap=0.3)
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                base = rad.solve(b.scene(rad), oracle=oracle, quality=0.3)
                scaled = rad.solve(scaled_scene(rad, b, scale=1000.0, emission_scale=1e-3), oracle=oracle, quality=0.3)
                self.assertEqual(scaled.stats["elements"], base.stats["elements"])
                self.assertEqual(scaled.stats["links"], base.stats["links"])
                # The solver works centred on the scene: a vertex at the origin
                # comes back within rounding of the scene's size, not of 0.
                np.testing.assert_allclose(scaled.positions, 1000 * base.positions, rtol=1e-12, atol=1e-9)
                np.testing.assert_allclose(scaled.radiance, 1e-3 * base.radiance, rtol=1e-4, atol=1e-9)

    def test_same_result_for_one_and_two_threads(self):
        b, _ = room_with_blocker()
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                one = rad.solve(b.scene(rad), oracle=oracle, quality=0.35, threads=1)
                two = rad.solve(b.scene(rad), oracle=oracle, quality=0.35, threads=2)
                for name in ("positions", "face_vertices", "face_sizes", "radiance", "source_face", "source_side"):
                    np.testing.assert_array_equal(getattr(one, name), getattr(two, name), err_msg=name)


class CrackFree(unittest.TestCase):
    def test_every_hanging_vertex_is_in_the_coarse_polygon(self):
        b, _ = room_with_blocker()
        result = rad.solve(b.scene(rad), oracle="perceptual", quality=0.35)
        polys = polygons(result)
        groups = {}
        for i, poly in enumerate(polys):
            groups.setdefault((result.source_face[i], result.source_side[i]), []).append(poly)
        hanging_seen = 0
        for group in groups.values():
            vertices = np.unique(np.concatenate(group))
            points = result.positions[vertices]
            for poly in group:
                hanging_seen += max(0, len(poly) - 4)
                for a, c in zip(poly, np.roll(poly, -1)):
                    pa, pc = result.positions[a], result.positions[c]
                    edge = pc - pa
                    t = (points - pa) @ edge / (edge @ edge)
                    off = np.linalg.norm(points - pa - t[:, None] * edge, axis=1)
                    inside = (t > 1e-9) & (t < 1 - 1e-9) & (off < 1e-9 * np.linalg.norm(edge))
                    self.assertFalse(inside.any(), "a vertex lies on a polygon edge but is not one of its corners")
        self.assertGreater(hanging_seen, 0, "the scene should have hanging vertices to check")


class BadInput(unittest.TestCase):
    def arrays(self):
        b = closed_box(0.5, 1.0)
        return b.arrays()

    def assert_error(self, pattern, **changes):
        a = self.arrays()
        a.update(changes)
        with self.assertRaisesRegex(ValueError, pattern):
            rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                      a.get("two_sided"))

    def test_reports_the_problem(self):
        a = self.arrays()
        bad_index = a["face_vertices"].copy()
        bad_index[5] = 999
        self.assert_error("face_vertices\\[5\\] = 999 is out of range", face_vertices=bad_index)
        negative = a["face_vertices"].copy()
        negative[0] = -1
        self.assert_error("out of range", face_vertices=negative)
        nan = a["positions"].copy()
        nan[3, 1] = np.nan
        self.assert_error("positions contains a non-finite value at vertex 3", positions=nan)
        self.assert_error("no faces", face_sizes=np.zeros(0, int), face_vertices=np.zeros(0, int),
                          reflectance=np.zeros((0, 3)), emission=np.zeros((0, 3)), two_sided=None)
        self.assert_error("positions must have shape", positions=a["positions"][:, :2])
        self.assert_error("reflectance must have shape", reflectance=a["reflectance"][:3])
        self.assert_error("adds up to", face_sizes=a["face_sizes"] + 1)
        self.assert_error("at least 3 vertices", face_sizes=np.array([2, 4, 4, 4, 4, 6]))
        self.assert_error("no emitter", emission=np.zeros_like(a["emission"]))
        too_bright = np.full((6, 3), 0.5)
        too_bright[1, 2] = 1.5
        self.assert_error("reflectance of face 1 is 1.5", reflectance=too_bright)
        negative = np.ones((6, 3))
        negative[0, 0] = -1
        self.assert_error("emission of face 0 is -1", emission=negative)
        self.assert_error("must hold integers", face_vertices=a["face_vertices"] + 0.5)
        self.assert_error("two_sided", two_sided=np.ones(4, bool))
        self.assert_error("must be an array", positions=None)

    def test_degenerate_faces_are_skipped_with_a_reason(self):
        a = self.arrays()
        positions = np.vstack([a["positions"], [[0, 0, 0], [1, 0, 0], [2, 0, 0]]])
        n = len(a["positions"])
        scene = rad.Scene(positions, np.concatenate([a["face_vertices"], [n, n + 1, n + 2]]),
                          np.concatenate([a["face_sizes"], [3]]), np.vstack([a["reflectance"], [[.5] * 3]]),
                          np.vstack([a["emission"], [[0] * 3]]))
        self.assertEqual(scene.skipped_faces, [{"face": 6, "kind": "collinear_corners"}])
        result = rad.solve(scene, quality=0.0)
        self.assertNotIn(6, result.source_face)

    def test_bad_options(self):
        scene = closed_box(0.5, 1.0).scene(rad)
        for kwargs, pattern in ((dict(oracle="bf"), "oracle must be"), (dict(quality=2.0), "quality"),
                                (dict(visibility="fast"), "visibility"), (dict(rays=0), "rays"),
                                (dict(max_elements=0), "max_elements"), (dict(time_budget=-1.0), "time_budget"),
                                (dict(bounces=0), "bounces"), (dict(threads=0), "threads"),
                                (dict(cancel="yes"), "CancelToken"), (dict(progress=3), "callable")):
            with self.subTest(**kwargs):
                with self.assertRaisesRegex(ValueError, pattern):
                    rad.solve(scene, **kwargs)


class Cancellation(unittest.TestCase):
    def test_cancel_from_another_thread_returns_promptly_with_a_valid_result(self):
        # The solve is held at its first refinement after pass 0 until another
        # thread has cancelled it: from there it may finish the work in flight,
        # but no more (counted in its reports, not in seconds).
        b, _ = room_with_blocker()
        scene = b.scene(rad)
        token = rad.CancelToken()
        reached, cancelled = threading.Event(), threading.Event()
        out = {"after": []}

        def progress(report):
            if cancelled.is_set():
                out["after"].append(report["phase"])
            elif report["phase"] == "refining" and report["pass"] >= 1:
                reached.set()
                cancelled.wait(timeout=60)

        def run():
            out["result"] = rad.solve(scene, oracle="gradient", quality=1.0, min_element_area=1e-7, cancel=token,
                                      progress=progress)

        worker = threading.Thread(target=run)
        worker.start()
        self.assertTrue(reached.wait(timeout=600))
        token.cancel()
        cancelled.set()
        worker.join(timeout=600)
        self.assertFalse(worker.is_alive())
        self.assertEqual(out["after"][-1], "done")
        self.assertNotIn("pass", out["after"])
        self.assertLessEqual(len(out["after"]), 2, out["after"])
        result = out["result"]
        self.assertTrue(result.stats["cancelled"])
        self.assertEqual(result.stats["stopped_by"], "cancel")
        self.assertEqual(result.stats["passes"], 1)  # pass 0, complete before the cancel
        self.assertTrue(np.all(np.isfinite(result.radiance)))
        self.assertEqual(result.face_vertices.size, result.face_sizes.sum())
        self.assertLess(result.face_vertices.max(), len(result.positions))
        # The last complete pass holds light, and no more than the converged
        # solution (each iteration carries light one bounce further).
        converged = reflected_power(rad.solve(scene, oracle="gradient", quality=0.3))
        self.assertGreater(reflected_power(result), 0.5 * converged)
        self.assertLess(reflected_power(result), 1.03 * converged)

    def test_failing_progress_callback_stops_the_solve_and_raises(self):
        b, _ = room_with_blocker()

        def progress(p):
            raise KeyError("from the callback")

        with self.assertRaises(KeyError):
            rad.solve(b.scene(rad), quality=0.3, progress=progress)

    def test_every_pass_snapshot_is_finite_and_holds_no_more_light_than_the_solution(self):
        b, _ = room_with_blocker()
        for oracle in ORACLES:
            converged = reflected_power(rad.solve(b.scene(rad), oracle=oracle, quality=1.0))
            for cancel_at in (1, 2, 3):
                token = rad.CancelToken()

                def progress(p):
                    if p["pass"] >= cancel_at:
                        token.cancel()

                result = rad.solve(b.scene(rad), oracle=oracle, quality=1.0, progress=progress, cancel=token)
                self.assertTrue(np.all(np.isfinite(result.radiance)))
                self.assertTrue(np.all(np.isfinite(result.irradiance)))
                self.assertLess(reflected_power(result), 1.03 * converged, (oracle, cancel_at))

    def test_progress_is_reported_per_pass(self):
        b, _ = room_with_blocker()
        seen = []
        result = rad.solve(b.scene(rad), oracle="perceptual", quality=0.3, progress=seen.append)
        passes = [p for p in seen if p["phase"] == "pass"]
        self.assertEqual(len(passes), result.stats["passes"])
        self.assertEqual(seen[-1]["phase"], "done")
        self.assertTrue(all(0 <= p["fraction"] <= 1 for p in seen))
        self.assertEqual([p["pass"] for p in passes], list(range(len(passes))))

    def test_progress_is_steady_and_ends_on_the_results_counts(self):
        # What a progress bar needs: the pass total known from the first report,
        # a fraction that never goes back, and final counts that are the result's.
        b, _ = room_with_blocker()
        for oracle in ORACLES:
            seen = []
            result = rad.solve(b.scene(rad), oracle=oracle, quality=0.5, progress=seen.append)
            self.assertEqual({p["passes"] for p in seen}, {result.stats["passes"]}, oracle)
            fractions = [p["fraction"] for p in seen]
            self.assertEqual(fractions, sorted(fractions), oracle)
            self.assertEqual(fractions[-1], 1.0)
            done = seen[-1]
            for key in ("elements", "leaves", "links"):
                self.assertEqual(done[key], result.stats[key], (oracle, key))
            # Leaves as reported while refining: the count the hierarchy has.
            for p in seen:
                self.assertLessEqual(p["leaves"], p["elements"])

    def test_progress_moves_within_each_pass(self):
        # The bar stood still while a pass refined (full_office: one value
        # while a pass went from 376 to 2,623 elements): within each pass the
        # refining and gathering reports move the fraction on, below the
        # pass's end.
        b, _ = room_with_blocker()
        for oracle in ORACLES:
            seen = []
            result = rad.solve(b.scene(rad), oracle=oracle, quality=0.5, progress=seen.append)
            ends = {p["pass"]: p["fraction"] for p in seen if p["phase"] == "pass"}
            self.assertEqual(len(ends), result.stats["passes"])
            for k, end in ends.items():
                within = {p["fraction"] for p in seen if p["pass"] == k and p["phase"] in ("refining", "gathering")}
                self.assertGreaterEqual(len(within), 3, (oracle, k, sorted(within)))
                self.assertLessEqual(max(within), end, (oracle, k))

    def test_each_pass_can_hand_over_its_solution(self):
        b, _ = room_with_blocker()
        seen = []
        result = rad.solve(b.scene(rad), oracle="perceptual", quality=0.5, progress=seen.append,
                           pass_results=True)
        passes = [p for p in seen if p["phase"] == "pass"]
        self.assertEqual(len(passes), result.stats["passes"])
        self.assertTrue(all("result" in p for p in passes))
        # Besides the passes' ends, only the rough look before linking (test_rough_look.py).
        others = [p for p in seen if p["phase"] != "pass" and "result" in p]
        self.assertEqual([(p["phase"], p["links"]) for p in others], [("linking", 0)])
        leaves = [p["result"].stats["leaves"] for p in passes]
        self.assertEqual(leaves, sorted(leaves))
        self.assertGreater(leaves[-1], leaves[0], "later passes refine")
        # The last pass's solution is the one returned.
        last = passes[-1]["result"]
        np.testing.assert_array_equal(last.radiance, result.radiance)
        np.testing.assert_array_equal(last.face_vertices, result.face_vertices)
        # Without asking, no copies are made.
        plain = []
        rad.solve(b.scene(rad), oracle="perceptual", quality=0.5, progress=plain.append)
        self.assertTrue(all("result" not in p for p in plain))

    def test_a_monitor_is_polled_from_another_thread(self):
        # Blender's UI polls a ProgressMonitor from its timer while the solve runs
        # on a worker thread: the reports and each pass's solution arrive there.
        import threading
        import time
        b, _ = room_with_blocker()
        monitor = rad.ProgressMonitor(pass_results=True)
        done = {}
        worker = threading.Thread(target=lambda: done.setdefault(
            "result", rad.solve(b.scene(rad), oracle="perceptual", quality=0.5, progress=monitor)))
        worker.start()
        polled, taken = [], []
        while worker.is_alive():
            report = monitor.progress()
            if report is not None:
                polled.append(report)
            pass_result = monitor.take_pass_result()
            if pass_result is not None:
                taken.append(pass_result)
            time.sleep(0.01)
        worker.join()
        result = done["result"]
        last = monitor.take_pass_result()
        if last is not None:
            taken.append(last)
        self.assertIsNone(monitor.take_pass_result(), "a solution is taken once")
        final = monitor.progress()
        self.assertEqual(final["phase"], "done")
        self.assertEqual(final["leaves"], result.stats["leaves"])
        fractions = [p["fraction"] for p in polled] + [final["fraction"]]
        self.assertEqual(fractions, sorted(fractions))
        self.assertGreaterEqual(len(taken), 1)
        np.testing.assert_array_equal(taken[-1].radiance, result.radiance)
        with self.assertRaises(ValueError):
            rad.solve(b.scene(rad), quality=0.0, progress=42)

    def test_yielding_to_an_interface_lowers_only_the_solves_threads(self):
        # Beside Blender's window the solve runs "nicer" than the window's thread;
        # the result is the same.
        b, _ = room_with_blocker()
        plain = rad.solve(b.scene(rad), oracle="standard", quality=0.3)
        seen = {}

        def work():
            seen["result"] = rad.solve(b.scene(rad), oracle="standard", quality=0.3, yield_to_interface=True)
            seen["nice"] = thread_niceness()

        before = thread_niceness()
        worker = threading.Thread(target=work)
        worker.start()
        worker.join()
        self.assertEqual(thread_niceness(), before, "the caller's other threads keep their priority")
        # The solve's threads go to niceness 5 (kSolveNiceness; Windows: one level
        # below normal) unless the caller already runs nicer (a test run under
        # `nice`), never back up.
        self.assertEqual(seen["nice"], max(before, LOWERED_NICENESS))
        np.testing.assert_array_equal(seen["result"].radiance, plain.radiance)

    def test_linking_a_large_scene_reports_progress(self):
        # The cluster walk and the face links each report as they go, so a
        # progress bar moves during a long initial linking.
        seen = []
        rad.solve(box_field(1000).scene(rad), oracle="standard", quality=0.0, visibility="sampled",
                  progress=seen.append)
        linking = [p["fraction"] for p in seen if p["phase"] == "linking"]
        self.assertGreater(sum(f <= 0.05 for f in linking), 2, "the walk reports")
        self.assertGreater(sum(f > 0.05 for f in linking), 0, "the face links report")
        self.assertEqual(linking, sorted(linking))


# How much this thread yields the CPU, larger = nicer: Linux's per-thread niceness;
# Windows' thread priority negated (the Windows module runs these tests under Wine).
if sys.platform == "win32":
    import ctypes
    _kernel32 = ctypes.WinDLL("kernel32")
    _kernel32.GetCurrentThread.restype = ctypes.c_void_p
    _kernel32.GetThreadPriority.argtypes = [ctypes.c_void_p]
    LOWERED_NICENESS = 1   # THREAD_PRIORITY_BELOW_NORMAL

    def thread_niceness():
        return -_kernel32.GetThreadPriority(_kernel32.GetCurrentThread())
else:
    LOWERED_NICENESS = 5   # kSolveNiceness

    def thread_niceness():
        return os.getpriority(os.PRIO_PROCESS, threading.get_native_id())


class QualityRange(unittest.TestCase):
    def test_coarsest_refines_nothing_and_converges(self):
        b, _ = room_with_blocker()
        scene = b.scene(rad)
        for oracle in ORACLES:
            result = rad.solve(scene, oracle=oracle, quality=0.0)
            sides = 2 * scene.patch_count - 1  # the light is one-sided
            self.assertEqual(result.stats["elements"], sides)
            self.assertLess(result.stats["residual"], 1e-6)

    def test_finest_is_bounded_by_budget_and_minimum_size(self):
        b, _ = room_with_blocker()
        scene = b.scene(rad)
        result = rad.solve(scene, oracle="perceptual", quality=1.0, max_elements=3000)
        self.assertLessEqual(result.stats["elements"], 3000)
        self.assertEqual(result.stats["stopped_by"], "max_elements")
        coarse = rad.solve(scene, oracle="perceptual", quality=1.0, min_element_area=2e-3)
        self.assertGreaterEqual(polygon_areas(coarse).min(), 2e-3 * scene.total_area * 0.999)

    def test_fixed_bounces(self):
        b = closed_box(0.5, 1.0)
        for bounces in (1, 2, 3):
            result = rad.solve(b.scene(rad), quality=0.0, bounces=bounces)
            expected = sum(0.5 ** k for k in range(bounces + 1))  # L_e (1 + rho + ... + rho^n)
            self.assertEqual(result.stats["iterations"], bounces)
            np.testing.assert_allclose(result.radiance, expected, rtol=1e-5)


class Memory(unittest.TestCase):
    def test_a_refined_solve_holds_no_growth_slack(self):
        # Per element: the Element (64 B), its vertices and midpoints, the
        # radiance it sends (24 B) and its energy-balance factors (44 B), about
        # 180 B once refinement has amortised what each patch holds. Arrays
        # grown by doubling and never given back held up to 220 B (issue 18).
        # A link is 40 B, 44 with its receiver grouping.
        scene = room_with_blocker()[0].scene(rad)
        for oracle in ORACLES:
            with self.subTest(oracle=oracle):
                stats = rad.solve(scene, oracle=oracle, quality=0.5).stats
                self.assertGreater(stats["elements"], 2000)
                self.assertLess(stats["bytes_per_element"], 185.0)
                self.assertLessEqual(stats["bytes_per_link"], 44.0)


if __name__ == "__main__":
    unittest.main()
