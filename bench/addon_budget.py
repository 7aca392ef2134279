"""The time budget through the add-on (issue 19), inside Blender: a plane of
about 200,000 faces under an emitting quad, solved by the Solve operator at
quality 1 with a time budget; prints the wall time of the whole operator
(export, solve, writing the result meshes) beside the solver's own seconds and
what stopped it. A measurement, not a test: the machine is shared.

    blender -b --factory-startup --python bench/addon_budget.py -- \
        --addon BUILD/addon [--faces 200000] [--budget 30]
"""

import argparse
import math
import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_common as common  # noqa: E402


def build(faces):
    """The plane (reflectance 0.5) and a 1 m emitting quad 2 m above it."""
    bpy.ops.wm.read_homefile(use_empty=True)
    cuts = max(1, round(math.sqrt(faces)))
    bpy.ops.mesh.primitive_grid_add(x_subdivisions=cuts + 1, y_subdivisions=cuts + 1, size=20.0)
    plane = bpy.context.active_object
    grey = bpy.data.materials.new("Grey")
    grey.diffuse_color = (0.5, 0.5, 0.5, 1.0)
    plane.data.materials.append(grey)
    bpy.ops.mesh.primitive_plane_add(size=1.0, location=(0.0, 0.0, 2.0), rotation=(math.pi, 0.0, 0.0))
    lamp = bpy.context.active_object
    light = bpy.data.materials.new("Light")
    light.use_nodes = True
    emission = light.node_tree.nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 50.0
    light.node_tree.links.new(emission.outputs[0], light.node_tree.nodes["Material Output"].inputs[0])
    lamp.data.materials.append(light)
    return len(plane.data.polygons)


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--addon", required=True)
    parser.add_argument("--faces", type=int, default=200000)
    parser.add_argument("--budget", type=float, default=30.0)
    args = parser.parse_args(sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else [])
    common.enable_addon(args.addon)
    faces = build(args.faces)
    settings = bpy.context.scene.radiosity
    settings.quality = 1.0
    settings.time_budget = args.budget
    start = time.perf_counter()
    outcome = bpy.ops.radiosity.solve()
    wall = time.perf_counter() - start
    stats = settings.stats
    common.say("addon budget: %d faces, budget %.0f s: operator %s in %.1f s (solver %.1f s, status %s, "
               "%d elements)" % (faces, args.budget, sorted(outcome)[0], wall, stats.seconds, stats.status,
                                 stats.elements))


main()
