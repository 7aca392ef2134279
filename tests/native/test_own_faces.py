"""A link's own faces never shadow it, in sampled visibility as in exact.

The solver skips the receiver's and the emitter's input faces when it looks for
what blocks a link: shaft culling leaves them out of the candidates (exact
visibility, and sampled visibility with few candidates), and past 32 candidates
sampled visibility casts its rays through Embree with a per-query filter that
rejects hits on them (native/core/visibility/ray_scene.cpp: a context filter function). An Embree
built without filter functions (EMBREE_FILTER_FUNCTION=OFF) ignores that filter
without an error, and every face folded or bent between a receiver and its
light then shadows it in sampled mode only. These tests run in the module the
package ships (the portable build, tools/portable_deps.py, with its own Embree),
so they hold that Embree to what Debian's Embree does for the C++ tests.

- visible_form_factor() with `faces` and `own_faces`: shadow rays that start on
  the receiver's face and end on the emitter's, with the rest of those faces
  folded across every ray, see the whole emitter; the same faces block when
  they are not the link's own, and other faces block as before.
- solve(): a quad folded into a valley, lit past its own other half, gets the
  same light with sampled as with exact visibility, through the Embree path.
"""

import unittest

import numpy as np

import _radiosity as rad
from kernels_module import MISSING, kernels
from synthetic_scenes import SceneBuilder

# The receiver point lies on wing A of face 0, whose wing B, folded along their
# shared edge (y = -1), rises over the point and covers every ray to the emitter.
WING_A = [(-1, -1, 0), (1, -1, 0), (0, 1, 0)]
WING_B = [(-1, -1, 0), (1, -1, 0), (0, 3, 2)]
POINT = np.array([0.0, 0.0, 0.0])
NORMAL = np.array([0.0, 0.0, 1.0])
# The emitter, facing down: face 1's two triangles, where the rays end. Its face
# also has a flap hanging under it (a lamp's shade bent down), as wide as the
# emitter's shadow at that height.
EMITTER = np.array([[-0.5, -0.5, 2.0], [-0.5, 0.5, 2.0], [0.5, 0.5, 2.0], [0.5, -0.5, 2.0]])
EMITTER_TRIANGLES = [EMITTER[[0, 1, 2]], EMITTER[[0, 2, 3]]]
FLAP = [(-2, -2, 1.5), (2, -2, 1.5), (0, 3, 1.5)]
# Another face, as large: a plain blocker.
BLOCKER = [(-2, -2, 1.0), (2, -2, 1.0), (0, 3, 1.0)]
RAYS = 64


def occluders(*parts):
    """(triangles (m, 3, 3), faces (m,)) of (face, [triangles]) parts."""
    triangles = [np.asarray(t, float) for _, ts in parts for t in ts]
    faces = [face for face, ts in parts for _ in ts]
    return np.array(triangles), np.array(faces)


@unittest.skipIf(kernels is None, MISSING)
class VisibleFormFactor(unittest.TestCase):
    def setUp(self):
        self.unoccluded, _ = kernels.form_factor_gradient(POINT, NORMAL, EMITTER)
        self.assertGreater(self.unoccluded, 0.05)

    def f(self, parts, mode, own_faces=(0, 1)):
        triangles, faces = occluders(*parts)
        value, _ = kernels.visible_form_factor(POINT, NORMAL, EMITTER, triangles, mode=mode, rays=RAYS,
                                           faces=faces, own_faces=own_faces)
        return value

    def test_the_folded_faces_cover_every_ray(self):
        # Not the link's own faces, they hide the emitter, in both modes: the
        # tests below are about skipping them, not about missing them.
        for parts in ([(0, [WING_A, WING_B]), (1, EMITTER_TRIANGLES)], [(1, EMITTER_TRIANGLES + [FLAP])]):
            for mode in ("exact", "sampled"):
                self.assertEqual(self.f(parts, mode, own_faces=()), 0.0, (mode, len(parts)))

    def test_the_receivers_own_face_never_shadows(self):
        parts = [(0, [WING_A, WING_B]), (1, EMITTER_TRIANGLES)]
        self.assertAlmostEqual(self.f(parts, "exact"), self.unoccluded, places=12)
        # No ray is blocked: the visible fraction is exactly 1.
        self.assertEqual(self.f(parts, "sampled"), self.unoccluded)
        self.assertEqual(self.f(parts, "sampled", own_faces=(0,)), self.unoccluded)

    def test_the_emitters_own_face_never_shadows(self):
        parts = [(0, [WING_A]), (1, EMITTER_TRIANGLES + [FLAP])]
        self.assertAlmostEqual(self.f(parts, "exact"), self.unoccluded, places=12)
        self.assertEqual(self.f(parts, "sampled"), self.unoccluded)
        self.assertEqual(self.f(parts, "sampled", own_faces=(7, 1)), self.unoccluded)

    def test_other_faces_still_shadow(self):
        parts = [(0, [WING_A, WING_B]), (1, EMITTER_TRIANGLES + [FLAP]), (2, [BLOCKER])]
        for mode in ("exact", "sampled"):
            self.assertEqual(self.f(parts, mode), 0.0, mode)
        # Only the receiver's face skipped: the flap of the emitter's face blocks.
        self.assertEqual(self.f(parts[:2], "sampled", own_faces=(0,)), 0.0)

    def test_bad_faces_are_value_errors(self):
        triangles, faces = occluders((0, [WING_A, WING_B]))
        for kwargs, message in ((dict(faces=faces[:1]), "faces"), (dict(faces=[0, -1]), "faces"),
                                (dict(faces=faces, own_faces=[0, 1, 2]), "own_faces"),
                                (dict(faces=faces, own_faces=[-3]), "own_faces")):
            with self.assertRaisesRegex(ValueError, message):
                kernels.visible_form_factor(POINT, NORMAL, EMITTER, triangles, mode="sampled", **kwargs)


def folded_quad_scene():
    """A quad folded along its diagonal B-D into a valley (its two triangles are
    one input face), a light beyond corner C that part of wing DAB sees only past
    wing BCD, and a comb of 40 small triangles between them, so that the links'
    shafts hold more than 32 candidates and sampled visibility goes through Embree."""
    b = SceneBuilder()
    # B first: a quad splits along its 0-2 diagonal (as Blender splits it).
    corners = [(2, 0, 0), (2, 2, 1.5), (0, 2, 0), (0, 0, 1.5)]   # B, C, D, A
    fold = b.polygon(corners, reflectance=0.5, two_sided=False)
    centre = np.array([3.2, 3.2, 1.2])
    facing = -np.array([1.0, 1.0, 0.2]) / np.linalg.norm([1.0, 1.0, 0.2])
    u = np.cross(facing, [0.0, 0.0, 1.0])
    u /= np.linalg.norm(u)
    v = np.cross(facing, u)
    light = b.polygon([centre + 0.3 * (su * u + sv * v) for su, sv in ((-1, -1), (1, -1), (1, 1), (-1, 1))],
                      reflectance=0.0, emission=20.0)
    rng = np.random.default_rng(1)
    start = np.array([0.6, 0.6, 0.6])
    for _ in range(40):
        p = start + (centre - start) * rng.uniform(0.2, 0.8) + rng.normal(0.0, 0.2, 3)
        b.polygon([p, p + [0.02, 0.0, 0.0], p + [0.0, 0.02, 0.01]], reflectance=0.5)
    return b, fold, light


class FoldedFaceSolve(unittest.TestCase):
    def test_sampled_matches_exact_through_embree(self):
        b, fold, _ = folded_quad_scene()
        scene = b.scene(rad)
        results = {mode: rad.solve(scene, oracle="standard", quality=0.0, visibility=mode, rays=RAYS, bounces=1)
                   for mode in ("exact", "sampled")}
        lit = {mode: r.irradiance[r.source_face == fold].mean(axis=1) for mode, r in results.items()}
        print("[own faces] folded quad's wings, irradiance: exact %s, sampled %s" % (lit["exact"], lit["sampled"]))
        self.assertEqual(len(lit["exact"]), 2)
        self.assertGreater(lit["exact"].max(), 0.05)
        np.testing.assert_allclose(lit["sampled"], lit["exact"], rtol=0.05, atol=1e-3 * lit["exact"].max())


if __name__ == "__main__":
    unittest.main()
