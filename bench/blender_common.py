"""What the study's Blender-side scripts share (runs inside Blender): arguments after
`--`, the add-on from a build tree, Lambertian materials, and the one render setup
every snapshot uses.

Every snapshot, of a radiosity solution, of a Cycles bake or of the path-traced
reference, is a Cycles render from the scene's camera, written as linear float
OpenEXR with the Standard view transform (radiance as stored), so all images share
exposure, anti-aliasing filter and pixel grid.
"""

import argparse
import json
import os
import sys

import addon_utils
import bpy

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "scenes"))
from scene_kit import make_lambertian  # noqa: E402

TAG = "[study] "
BOUNCES = ("max_bounces", "diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
           "transparent_max_bounces")


def say(message):
    print(TAG + message, flush=True)


def arguments(parser: argparse.ArgumentParser):
    return parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])


def enable_addon(addon_dir):
    """Enable the add-on from a build tree without touching the preferences."""
    sys.path.insert(0, addon_dir)

    def fail(err):
        raise err

    addon_utils.enable("radiosity", default_set=False, handle_error=fail)


def start_jobs():
    """The common start of a jobs script: --addon and --jobs after `--`, the add-on
    enabled, the scene's materials made Lambertian; returns the jobs (a dict)."""
    parser = argparse.ArgumentParser()
    parser.add_argument("--addon", required=True)
    parser.add_argument("--jobs", required=True)
    args = arguments(parser)
    with open(args.jobs) as f:
        jobs = json.load(f)
    enable_addon(args.addon)
    lambertian_scene()
    return jobs


def lambertian_scene():
    for material in bpy.data.materials:
        make_lambertian(material)


def setup_render(scene, width, height, samples, seed=0, path_traced=False):
    """Cycles CPU, no denoiser, no adaptive sampling, fixed seed, linear EXR.

    Snapshots of baked colours (path_traced=False) see only emission: no bounce is
    needed, and the samples only anti-alias; with the same seed every snapshot
    has the same pixel jitter, so geometry edges cancel in differences. The
    reference keeps the scene's bounce settings (32, no clamping)."""
    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    scene.cycles.seed = seed
    scene.cycles.use_animated_seed = False
    scene.cycles.use_denoising = False
    scene.cycles.use_adaptive_sampling = False
    # The scene's own bounce settings, remembered on the first call, serve path tracing.
    if "study_bounces" not in scene:
        scene["study_bounces"] = {k: getattr(scene.cycles, k) for k in BOUNCES}
    for key, value in scene["study_bounces"].items():
        setattr(scene.cycles, key, value)
    if not path_traced:
        # Camera rays stop at the first (emitting) surface; only the
        # transparent back faces of the result meshes are passed through.
        scene.cycles.max_bounces = 8
        for kind in ("diffuse", "glossy", "transmission", "volume"):
            setattr(scene.cycles, kind + "_bounces", 0)
        scene.cycles.transparent_max_bounces = 8
    scene.render.resolution_x, scene.render.resolution_y = width, height
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0
    settings = scene.render.image_settings
    settings.file_format = 'OPEN_EXR'
    settings.color_depth = '32'
    settings.exr_codec = 'ZIP'
    settings.color_mode = 'RGB'


def render_to(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    if not os.path.exists(path):
        raise RuntimeError("render did not write %s" % path)


def camera_projection(scene):
    """World -> pixel mapping of the scene camera: a 3 x 4 matrix P such that for a
    world point x, (a, b, q) = P (x, 1) gives pixel column a/q, row b/q (top row
    0, pixel centres at +0.5) and q, the depth along the camera's view axis."""
    import numpy as np
    cam = scene.camera
    depsgraph = bpy.context.evaluated_depsgraph_get()
    width, height = scene.render.resolution_x, scene.render.resolution_y
    m = np.array(cam.calc_matrix_camera(depsgraph, x=width, y=height)) @ np.array(cam.matrix_world.inverted())
    # Clip (x, y, z, w) -> NDC x/w, y/w in [-1, 1], y up; w = -z_camera for a perspective camera.
    return np.vstack([width / 2 * (m[0] + m[3]), height / 2 * (m[3] - m[1]), m[3]]).tolist()


def write_json(path, data):
    with open(path, "w") as f:
        json.dump(data, f, indent=1)
