"""Study step 1 (inside Blender): the solver's input arrays of a scene, as the add-on
exports them, so the sweep can solve outside Blender (no Blender overhead in the
timings, and nothing else running while it times).

    blender -b --factory-startup SCENE.blend --python bench/blender_export.py -- \
        --addon BUILD/addon --out SCENE.npz

Materials are made Lambertian first, the same change every other study step makes.
"""

import argparse
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_common as common  # noqa: E402


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--addon", required=True)
    parser.add_argument("--out", required=True)
    args = common.arguments(parser)
    common.enable_addon(args.addon)
    from radiosity.model import findings
    from radiosity.read import export

    common.lambertian_scene()
    exported = export.export_scene(bpy.context)
    a = exported.arrays
    np.savez(args.out, positions=a["positions"], face_vertices=a["face_vertices"], face_sizes=a["face_sizes"],
             reflectance=a["reflectance"], emission=a["emission"], two_sided=a["two_sided"])
    common.say("exported %d faces (%s)" % (exported.face_count, findings.unmodelled_message(exported.unmodelled)
                                          or "everything modelled"))


if __name__ == "__main__":
    main()
