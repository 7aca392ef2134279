"""Direct light from lights that are not surfaces (native/core/solve/direct_light.h):
point, spot and sun lights and a uniform world, against closed forms.

Units: a receiver gathers H (irradiance / pi, radiance units) and shows
L = L_e + rho H. A point light of intensity I gives H = I cos(theta) / d^2;
a sun of irradiance E gives H = E cos(theta); a world of radiance L_w gives
H = L_w times the form factor of the open sky.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box  # noqa: E402
from test_solver import ORACLES, polygon_areas  # noqa: E402


def scene_of(builder, lights=None, world=None, scale=1.0):
    a = builder.arrays()
    return rad.Scene(a["positions"] * scale, a["face_vertices"], a["face_sizes"], a["reflectance"],
                     a["emission"], a["two_sided"], lights=lights, world=world)


def floor(size=4.0, rho=0.5, two_sided=False):
    """A square floor in z = 0 facing up, centred on the origin."""
    b = SceneBuilder()
    h = size / 2
    b.polygon([(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], reflectance=(rho,) * 3, two_sided=two_sided)
    return b


def point_light_H(points, light_pos, normal, intensity):
    d = np.asarray(light_pos) - points
    dist = np.linalg.norm(d, axis=1)
    return intensity * np.maximum(d @ normal, 0) / dist ** 3


def vertices_facing(result, normal, tol=1e-6):
    """Indices of result vertices used by polygons whose normal is `normal`."""
    pos = np.asarray(result.positions)
    sizes = np.asarray(result.face_sizes)
    starts = np.cumsum(sizes) - sizes
    fv = np.asarray(result.face_vertices)
    keep = []
    for s, n in zip(starts, sizes):
        a, b, c = pos[fv[s]], pos[fv[s + 1]], pos[fv[s + 2]]
        nn = np.cross(b - a, c - a)
        nn /= np.linalg.norm(nn)
        if np.dot(nn, normal) > 1 - tol:
            keep.extend(fv[s:s + n])
    return np.unique(keep)


class PointLight(unittest.TestCase):
    def test_inverse_square_and_cosine_at_every_vertex(self):
        light = {"type": "point", "position": (0.3, -0.2, 1.5), "intensity": (2.0, 1.0, 0.5)}
        for quality in (0.0, 0.5):
            result = rad.solve(scene_of(floor(), [light]), oracle="perceptual", quality=quality)
            expected = point_light_H(result.positions, light["position"], np.array([0, 0, 1]), 1.0)
            np.testing.assert_allclose(result.vertex_irradiance, expected[:, None] * light["intensity"],
                                       rtol=1e-5, atol=1e-7)
            np.testing.assert_allclose(result.radiance, 0.5 * result.vertex_irradiance, rtol=1e-6)
            self.assertGreater(result.stats["light_links"], 0)

    def test_refinement_follows_the_light(self):
        # The oracles see a point light like any emitter: a bright spot under
        # a low light refines the floor there, a black world does not.
        light = {"type": "point", "position": (0.0, 0.0, 0.3), "intensity": (1.0, 1.0, 1.0)}
        for oracle in ORACLES:
            coarse = rad.solve(scene_of(floor(), [light]), oracle=oracle, quality=0.0)
            fine = rad.solve(scene_of(floor(), [light]), oracle=oracle, quality=0.6)
            self.assertEqual(coarse.stats["leaves"], 1)
            self.assertGreater(fine.stats["leaves"], 16, oracle)
            # Absorbed power converges to the exact integral of I cos / d^2
            # over the square: pi (1 - rho) x that.
            absorbed = (np.asarray(fine.irradiance)[:, 0] * polygon_areas(fine)).sum()
            self.assertAlmostEqual(absorbed, square_integral(2.0, 0.3), delta=0.02 * square_integral(2.0, 0.3))

    def test_a_box_casts_a_hard_shadow(self):
        b = floor()
        add_box(b, (-0.5, -0.5, 0.5), (0.5, 0.5, 0.7), reflectance=(0.5,) * 3)
        light = {"type": "point", "position": (0.0, 0.0, 2.0), "intensity": (1.0, 1.0, 1.0)}
        for visibility in ("exact", "sampled"):
            result = rad.solve(scene_of(b, [light]), quality=0.5, visibility=visibility)
            pos = np.asarray(result.positions)
            on_floor = np.abs(pos[:, 2]) < 1e-6
            # The box's shadow on the floor reaches |x|, |y| < 0.5 * 2 / 1.3 (its top edge).
            umbra = on_floor & (np.abs(pos[:, 0]) < 0.6) & (np.abs(pos[:, 1]) < 0.6)
            lit = on_floor & ((np.abs(pos[:, 0]) > 0.8) | (np.abs(pos[:, 1]) > 0.8))
            h = np.asarray(result.vertex_irradiance)[:, 0]
            direct = point_light_H(pos, light["position"], np.array([0, 0, 1]), 1.0)
            self.assertTrue(np.all(h[umbra] < 0.2 * direct[umbra]), visibility)  # only bounce light
            self.assertTrue(np.all(h[lit] >= direct[lit] * (1 - 1e-5)), visibility)

    def test_a_sphere_light_gives_the_sphere_form_factor(self):
        # A sphere of radius r and intensity I (radiance I / r^2) above the
        # horizon gives H = I cos / d^2 exactly; its 16-gon, within 1 %.
        light = {"type": "point", "position": (0.0, 0.0, 0.5), "intensity": (1.0, 1.0, 1.0), "radius": 0.2}
        result = rad.solve(scene_of(floor(), [light]), quality=0.0)
        pos = np.asarray(result.positions)
        expected = point_light_H(pos, light["position"], np.array([0, 0, 1]), 1.0)
        np.testing.assert_allclose(np.asarray(result.vertex_irradiance)[:, 0], expected, rtol=0.01)

    def test_scale_invariance(self):
        # Positions x k, intensity x k^2: the same radiance.
        b = floor()
        add_box(b, (-0.5, -0.5, 0.5), (0.5, 0.5, 0.7), reflectance=(0.5,) * 3)
        light = {"type": "point", "position": (0.2, 0.1, 2.0), "intensity": (1.0, 1.0, 1.0), "radius": 0.1}
        base = rad.solve(scene_of(b, [light]), quality=0.5)
        k = 1000.0
        big = dict(light, position=tuple(np.array(light["position"]) * k), intensity=(k * k,) * 3, radius=0.1 * k)
        scaled = rad.solve(scene_of(b, [big], scale=k), quality=0.5)
        self.assertEqual(base.stats["leaves"], scaled.stats["leaves"])
        # Float32 output and tolerances relative to sizes: equal to 1e-4 of the brightest.
        np.testing.assert_allclose(scaled.radiance, base.radiance, rtol=1e-4,
                                   atol=1e-4 * np.max(base.radiance))


def square_integral(half, height):
    """Integral of h / (h^2 + r^2)^(3/2) over the square [-a, a]^2 at height h:
    the form factor sum (4 times the point-to-rectangle corner integral)."""
    a, h = half, height
    # integral over [0,a]x[0,a] of h / (h^2+x^2+y^2)^(3/2) dx dy = atan(a^2 / (h sqrt(h^2 + 2 a^2)))
    return 4 * math.atan(a * a / (h * math.sqrt(h * h + 2 * a * a)))


class SpotLight(unittest.TestCase):
    def test_cone_and_blend(self):
        cos_half = math.cos(math.radians(30))
        light = {"type": "spot", "position": (0.0, 0.0, 1.0), "intensity": (1.0, 1.0, 1.0),
                 "direction": (0.0, 0.0, -1.0), "cos_half_angle": cos_half, "blend_width": 0.05}
        result = rad.solve(scene_of(floor(), [light]), quality=0.3)
        pos = np.asarray(result.positions)
        d = pos - np.array(light["position"])
        c = -d[:, 2] / np.linalg.norm(d, axis=1)
        t = np.clip((c - cos_half) / 0.05, 0, 1)
        expected = t * t * (3 - 2 * t) * point_light_H(pos, light["position"], np.array([0, 0, 1]), 1.0)
        np.testing.assert_allclose(np.asarray(result.vertex_irradiance)[:, 0], expected, rtol=1e-5, atol=1e-7)
        self.assertTrue(np.any(expected == 0) and np.any((t > 0) & (t < 1)))
        # The cone's edge is refined: elements are smaller there.
        self.assertGreater(result.stats["leaves"], 16)

    def test_cosine_falloff(self):
        cos_half = math.cos(math.radians(60))
        light = {"type": "spot", "position": (0.0, 0.0, 1.0), "intensity": (1.0, 1.0, 1.0),
                 "direction": (0.0, 0.0, -1.0), "cos_half_angle": cos_half, "blend_width": 0.0,
                 "cosine_falloff": True}
        result = rad.solve(scene_of(floor(), [light]), quality=0.0)
        pos = np.asarray(result.positions)
        d = pos - np.array(light["position"])
        c = -d[:, 2] / np.linalg.norm(d, axis=1)
        expected = np.where(c > cos_half, c, 0) * point_light_H(pos, light["position"], np.array([0, 0, 1]), 1.0)
        np.testing.assert_allclose(np.asarray(result.vertex_irradiance)[:, 0], expected, rtol=1e-5, atol=1e-7)


class Sun(unittest.TestCase):
    def test_cosine_and_shadow(self):
        b = floor()
        add_box(b, (-0.5, -0.5, 0.5), (0.5, 0.5, 0.7), reflectance=(0.0,) * 3)  # black: no bounce
        tilt = math.radians(30)
        direction = (math.sin(tilt), 0.0, -math.cos(tilt))
        for angle in (0.0, math.radians(2.0)):
            sun = {"type": "sun", "direction": direction, "irradiance": (3.0, 3.0, 3.0), "angle": angle}
            result = rad.solve(scene_of(b, [sun]), quality=0.5)
            pos = np.asarray(result.positions)
            h = np.asarray(result.vertex_irradiance)[:, 0]
            on_floor = np.abs(pos[:, 2]) < 1e-6
            # The shadow of the box, shifted along +x by z tan(tilt).
            shift = 0.6 * math.tan(tilt)
            umbra = on_floor & (np.abs(pos[:, 0] - shift) < 0.35) & (np.abs(pos[:, 1]) < 0.45)
            lit = on_floor & ((np.abs(pos[:, 0] - shift) > 0.7) | (np.abs(pos[:, 1]) > 0.65))
            self.assertTrue(np.all(h[umbra] == 0), angle)
            np.testing.assert_allclose(h[lit], 3.0 * math.cos(tilt), rtol=2e-3, err_msg=str(angle))


class World(unittest.TestCase):
    def test_open_floor_sees_the_whole_sky(self):
        result = rad.solve(scene_of(floor(), world=(0.2, 0.3, 0.4)), quality=0.0)
        np.testing.assert_allclose(result.vertex_irradiance, np.tile([0.2, 0.3, 0.4], (len(result.positions), 1)),
                                   rtol=1e-6)

    def test_a_closed_box_sees_no_sky(self):
        b = SceneBuilder()
        add_box(b, (0, 0, 0), (1, 1, 1), reflectance=(0.5,) * 3, inward=True)
        result = rad.solve(scene_of(b, world=(1.0, 1.0, 1.0)), quality=0.5)
        pos = np.asarray(result.positions)
        # The floor's inner side faces up and sees only the box: no light
        # reaches it, so it is not shown; its outer side faces down, open to
        # the sky below.
        inner = vertices_facing(result, np.array([0, 0, 1]))
        self.assertEqual(len(inner[np.abs(pos[inner, 2]) < 1e-6]), 0)
        sides = set(zip(np.asarray(result.source_face).tolist(), np.asarray(result.source_side).tolist()))
        self.assertEqual(len(sides), 6)  # each face once: its outer side
        outer = vertices_facing(result, np.array([0, 0, -1]))
        floor_outer = outer[np.abs(pos[outer, 2]) < 1e-6]
        self.assertGreater(len(floor_outer), 0)
        np.testing.assert_allclose(np.asarray(result.vertex_irradiance)[floor_outer], 1.0, rtol=1e-6)

    def test_sky_through_a_window_is_the_window_form_factor(self):
        # A closed black box with a square hole in its roof: the floor's centre
        # sees the sky through the hole only: H = L_w x F(point -> square).
        b = SceneBuilder()
        add_box(b, (-1, -1, 0), (1, 1, 1), reflectance=(0.0,) * 3, inward=True, omit=("top",))
        for x0, x1, y0, y1 in ((-1, 1, -1, -0.25), (-1, 1, 0.25, 1), (-1, -0.25, -0.25, 0.25), (0.25, 1, -0.25, 0.25)):
            b.polygon([(x0, y1, 1), (x1, y1, 1), (x1, y0, 1), (x0, y0, 1)], reflectance=(0.0,) * 3)
        b.polygon([(-0.1, -0.1, 0.001), (0.1, -0.1, 0.001), (0.1, 0.1, 0.001), (-0.1, 0.1, 0.001)], reflectance=(0.5,) * 3,
                  two_sided=False)
        result = rad.solve(scene_of(b, world=(1.0, 1.0, 1.0)), quality=0.0)
        pos = np.asarray(result.positions)
        probe = np.flatnonzero((np.abs(pos[:, 2] - 0.001) < 1e-9))
        self.assertEqual(len(probe), 4)
        h = 0.999
        a = 0.25
        for v in probe:
            x, y = pos[v, :2]
            # Inclusion-exclusion over the window's corners, signed corner rectangles.
            expected = sum(np.sign(cx) * np.sign(cy) * np.sign(cx - x) * np.sign(cy - y)
                           * rect_corner_ff(abs(cx - x), abs(cy - y), h) for cx in (-a, a) for cy in (-a, a))
            self.assertAlmostEqual(result.vertex_irradiance[v][0], expected, delta=1e-4 * max(expected, 1e-3))


def rect_corner_ff(a, b, h):
    """Form factor from a point to the a x b rectangle with a corner above it, at height h, parallel."""
    x, y = a / h, b / h
    return (x / math.sqrt(1 + x * x) * math.atan(y / math.sqrt(1 + x * x))
            + y / math.sqrt(1 + y * y) * math.atan(x / math.sqrt(1 + y * y))) / (2 * math.pi)


class Validation(unittest.TestCase):
    def test_bad_lights_are_refused_clearly(self):
        b = floor()
        cases = [
            ([{"type": "torch", "position": (0, 0, 1), "intensity": (1, 1, 1)}], "type"),
            ([{"type": "point", "intensity": (1, 1, 1)}], "position"),
            ([{"type": "point", "position": (0, 0, 1), "intensity": (1, 1, float("nan"))}], "intensity"),
            ([{"type": "point", "position": (0, 0, 1), "intensity": (1, 1, -1)}], "colour"),
            ([{"type": "point", "position": (0, 0, 1), "intensity": (1, 1, 1), "radius": -1}], "radius"),
            ([{"type": "point", "position": (0, 0, 1), "intensity": (1, 1, 1), "colour": 2}], "colour"),
            ([{"type": "sun", "direction": (0, 0, 0), "irradiance": (1, 1, 1)}], "direction"),
            ([{"type": "spot", "position": (0, 0, 1), "intensity": (1, 1, 1), "direction": (0, 0, -1),
               "cos_half_angle": 2.0}], "cos_half_angle"),
            ("point", "list"),
        ]
        for lights, word in cases:
            with self.assertRaises(ValueError, msg=str(lights)) as caught:
                scene_of(b, lights)
            self.assertIn(word, str(caught.exception))
        with self.assertRaises(ValueError):
            scene_of(b, world=(1, -1, 1))

    def test_a_scene_lit_only_by_a_light_solves(self):
        # No emissive face at all: the light alone is enough.
        result = rad.solve(scene_of(floor(), [{"type": "sun", "direction": (0, 0, -1), "irradiance": (1, 1, 1)}]))
        np.testing.assert_allclose(result.vertex_irradiance, 1.0, rtol=1e-6)
        with self.assertRaises(ValueError):
            scene_of(floor())


if __name__ == "__main__":
    unittest.main()
