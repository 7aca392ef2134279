"""Builds one bundled scene and saves it (runs inside Blender).

    blender -b --factory-startup --python scenes/build_scene.py -- NAME OUT.blend

NAME is one of catalog.SCENES, CONTACT_SCENES, LIGHT_SCENES or TESSELLATED_SCENES; each has a module NAME.py
here with build(scene).
"""

import importlib
import os
import sys

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

import catalog  # noqa: E402  (needs the path above)
import scene_kit  # noqa: E402


def build(name, scene, **params):
    """Fill `scene` (empty) with the scene called `name`; `params` go to its
    builder (e.g. the Cornell box's gap=0.01)."""
    known = {**catalog.SCENES, **catalog.CONTACT_SCENES, **catalog.LIGHT_SCENES, **catalog.TESSELLATED_SCENES}
    if name not in known:
        raise ValueError("unknown scene %r; known: %s" % (name, ", ".join(known)))
    importlib.import_module(name).build(scene, **params)


def main(argv):
    args = argv[argv.index("--") + 1:] if "--" in argv else []
    if len(args) != 2:
        sys.exit("usage: blender -b --factory-startup --python build_scene.py -- NAME OUT.blend")
    name, out = args
    scene = scene_kit.empty_file()
    scene.name = name
    build(name, scene)
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.abspath(out))
    print("built scene %r: %s" % (name, out))


if __name__ == "__main__":
    main(sys.argv)
