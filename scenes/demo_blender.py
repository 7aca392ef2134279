"""The Blender side of demo.py: enable the add-on, solve, save, render.

    blender -b --factory-startup SCENE.blend --python demo_blender.py -- --addon BUILD/addon \
        --oracle PERCEPTUAL --samples 32 --blend OUT.blend --png OUT.png

Lines meant for the user start with "[demo] "; demo.py shows only those.
"""

import argparse
import sys
import time

import addon_utils
import bpy


def say(message):
    print("[demo] " + message, flush=True)


def parse_args():
    parser = argparse.ArgumentParser()
    parser.add_argument("--addon", required=True, help="folder holding the radiosity package")
    parser.add_argument("--oracle", default="PERCEPTUAL")
    parser.add_argument("--samples", type=int, default=32)
    parser.add_argument("--blend", required=True)
    parser.add_argument("--png", required=True)
    return parser.parse_args(sys.argv[sys.argv.index("--") + 1:])


def enable_addon(path):
    """Enable the add-on the way Preferences does, from `path` instead of the
    scripts folder, without recording it in the preferences."""
    sys.path.insert(0, path)

    def fail(err):
        raise err

    addon_utils.enable("radiosity", default_set=False, handle_error=fail)


def solve(scene, oracle):
    """Run the solve operator; True if it finished. A cancelled solve is reported, not fatal."""
    scene.radiosity.oracle = oracle
    start = time.perf_counter()
    try:
        result = bpy.ops.radiosity.solve()
    except RuntimeError as err:
        # The operator reports errors; bpy.ops raises them as RuntimeError.
        say("solve not done: %s" % str(err).strip().removeprefix("Error: "))
        say("rendering the unsolved scene (path traced)")
        return False
    if result != {'FINISHED'}:
        say("solve %s; rendering the unsolved scene" % ", ".join(sorted(result)).lower())
        return False
    stats = scene.radiosity.stats
    say("solved with the %s oracle in %.1f s: %d elements, %d links (%s)"
        % (oracle.lower(), time.perf_counter() - start, stats.elements, stats.links, stats.status))
    return True


def render(scene, path, samples):
    # After a solve the camera sees only the result meshes, whose material
    # emits the baked radiance: no light transport left, so a few samples (for
    # anti-aliasing) give a noise-free image. Unsolved, it is a quick path-traced
    # preview: no denoiser (not in every Blender build), indirect light clamped
    # against fireflies. This changes only the preview render: the saved .blend
    # keeps the scene's settings.
    scene.cycles.samples = samples
    scene.cycles.use_denoising = False
    scene.cycles.sample_clamp_indirect = 1.0
    scene.cycles.device = 'CPU'
    scene.render.image_settings.file_format = 'PNG'
    scene.render.filepath = path
    start = time.perf_counter()
    bpy.ops.render.render(write_still=True)
    say("rendered %dx%d, %d samples, in %.1f s"
        % (scene.render.resolution_x, scene.render.resolution_y, samples, time.perf_counter() - start))


def show_result_in_viewport(scene):
    """Solid shading shows the attribute; the saved file opens on the solution."""
    for screen in bpy.data.screens:
        for area in screen.areas:
            for space in area.spaces:
                if space.type == 'VIEW_3D':
                    space.shading.type = 'SOLID'
                    space.shading.light = 'FLAT'   # the colours are the lighting


def main():
    args = parse_args()
    enable_addon(args.addon)
    scene = bpy.context.scene
    if solve(scene, args.oracle):
        show_result_in_viewport(scene)
    bpy.ops.wm.save_as_mainfile(filepath=args.blend)
    render(scene, args.png, args.samples)


if __name__ == "__main__":
    main()
