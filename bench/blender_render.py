"""Study snapshots (inside Blender): renders of radiosity solutions and of the
path-traced reference, from the scene's camera, as linear EXR.

    blender -b --factory-startup SCENE.blend --python bench/blender_render.py -- \
        --addon BUILD/addon --jobs JOBS.json

JOBS.json: {"width", "height", "samples", "camera": OUT.json (optional),
"mask": OUT.npy (optional), "solutions": [{"npz", "exr", "edges" (optional)}],
"references": [{"exr", "samples", "seed"}]}.

- A solution (arrays of a Result saved by the sweep) is baked into the scene by
  the add-on's own bake (result meshes emitting their radiance, originals
  hidden) and rendered with few samples: there is no light transport left, the
  samples only anti-alias. With "edges" (.npy), the pieces of mesh edges the camera
  sees are written too, in pixels (for the wireframe figures).
- A reference is the original scene (Lambertian materials) path traced with the
  scene's bounce settings, at the given samples and seed.
- "camera" receives the world -> pixel projection (blender_common.camera_projection).
- "mask" receives the (H, W) bool array of the pixels the emitters cover
  (tests/blender/render_compare.emitter_mask), left out of the exposure error.
"""

import os
import sys
import time
from types import SimpleNamespace

import bpy
import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "tests", "blender"))
import blender_common as common  # noqa: E402
import render_compare  # noqa: E402  (the emitter mask the agreement tests use)

# Each edge is cut into this many pieces, each kept if its midpoint is seen.
EDGE_PIECES = 5


def load_result(path):
    d = np.load(path)
    return SimpleNamespace(**{k: d[k] for k in ("positions", "face_vertices", "face_sizes", "radiance",
                                                "vertex_irradiance", "source_face", "source_side")})


def visible_edges(scene, result, projection):
    """(S, 2, 2) pixel end points of the pieces of mesh edges the camera sees.

    Edges of polygons facing the camera, cut into EDGE_PIECES pieces; a piece is
    kept if a ray from the camera reaches its midpoint unblocked, and is clipped
    to the space in front of the camera (room walls reach behind it)."""
    positions = np.asarray(result.positions, dtype=float)
    sizes = np.asarray(result.face_sizes)
    corners = np.asarray(result.face_vertices)
    starts = np.cumsum(sizes) - sizes
    cam = np.array(scene.camera.matrix_world.translation)
    polygons = [corners[s:s + n].tolist() for s, n in zip(starts, sizes)]
    tree = BVHTree.FromPolygons(positions.tolist(), polygons, all_triangles=False, epsilon=0.0)
    edges = set()
    for poly in polygons:
        p = positions[poly]
        normal = np.cross(p[1] - p[0], p[2] - p[0])
        if np.dot(normal, cam - p[0]) <= 0:      # the side facing away is the other polygon
            continue
        for a, b in zip(poly, poly[1:] + poly[:1]):
            edges.add((min(a, b), max(a, b)))
    P = np.array(projection)
    near = 1e-3 * float(np.ptp(positions, axis=0).max())
    origin = Vector(cam)
    pieces = []
    for a, b in sorted(edges):
        for k in range(EDGE_PIECES):
            x0 = positions[a] + (positions[b] - positions[a]) * k / EDGE_PIECES
            x1 = positions[a] + (positions[b] - positions[a]) * (k + 1) / EDGE_PIECES
            mid = 0.5 * (x0 + x1)
            d = mid - cam
            dist = float(np.linalg.norm(d))
            hit = tree.ray_cast(origin, Vector(d / dist), dist * 1.01)
            if hit[0] is not None and hit[3] < dist * (1 - 2e-3):
                continue
            h0, h1 = P @ np.append(x0, 1.0), P @ np.append(x1, 1.0)
            if h0[2] < near and h1[2] < near:
                continue
            if h0[2] < near or h1[2] < near:   # clip at the near plane, in homogeneous space
                t = (near - h0[2]) / (h1[2] - h0[2])
                clipped = h0 + t * (h1 - h0)
                h0, h1 = (clipped, h1) if h0[2] < near else (h0, clipped)
            pieces.append([h0[:2] / h0[2], h1[:2] / h1[2]])
    return np.array(pieces, dtype=float).reshape(-1, 2, 2)


def render_solutions(scene, jobs, exported, projection):
    from radiosity.write import bake, result_state
    for job in jobs:
        result = load_result(job["npz"])
        bake.write_refined(scene, exported, result)
        result_state.hide_originals(scene, bpy.context.view_layer, exported.hidden_sources)
        result_state.show_results(scene, True)
        start = time.perf_counter()
        common.render_to(scene, job["exr"])
        common.say("rendered %s (%d polygons) in %.1f s" % (os.path.basename(job["exr"]), len(result.face_sizes),
                                                           time.perf_counter() - start))
        if job.get("edges"):
            np.save(job["edges"], visible_edges(scene, result, projection))


def main():
    jobs = common.start_jobs()
    from radiosity.read import export
    from radiosity.write import result_state

    scene = bpy.context.scene
    width, height = jobs["width"], jobs["height"]
    # Path-traced settings first: the references need the scene's own bounces.
    common.setup_render(scene, width, height, jobs.get("samples", 16), path_traced=True)
    projection = common.camera_projection(scene)
    if jobs.get("camera"):
        common.write_json(jobs["camera"], {"projection": projection, "width": width, "height": height})
    for ref in jobs.get("references", []):
        common.setup_render(scene, width, height, ref["samples"], seed=ref["seed"], path_traced=True)
        start = time.perf_counter()
        common.render_to(scene, ref["exr"])
        common.say("reference %s: %d samples in %.1f s" % (os.path.basename(ref["exr"]), ref["samples"],
                                                           time.perf_counter() - start))
    if jobs.get("mask"):
        np.save(jobs["mask"], render_compare.emitter_mask(scene, resolution=(width, height)))
    if jobs.get("solutions"):
        common.setup_render(scene, width, height, jobs.get("samples", 16))
        exported = export.export_scene(bpy.context)
        render_solutions(scene, jobs["solutions"], exported, projection)
        result_state.remove_results(scene)


if __name__ == "__main__":
    main()
