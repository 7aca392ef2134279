"""Blender side of test_package.py: install a package zip in this (clean) Blender, solve,
compare with Cycles, report.

    blender -b --factory-startup --python install_and_solve.py -- \
        extension|legacy ZIP SCENES_DIR QUALITY REFERENCE_SAMPLES IMAGES_DIR

Builds the bundled cube scene with Lambertian materials and renders its Cycles
reference (REFERENCE_SAMPLES), installs ZIP with one of Blender's installers
(extension: into the "user_default" repository; legacy: the add-on installer of
Preferences > Add-ons, as in 3.x), enables it,
solves at QUALITY, renders the baked solution (16 samples, as test_cycles.py),
saves both images as .npy in IMAGES_DIR and prints one line "RESULT <json>".
"""

import importlib
import json
import os
import sys

import addon_utils
import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import render_compare as rc  # noqa: E402

KIND, ZIP, SCENES, QUALITY, REFERENCE_SAMPLES, IMAGES = sys.argv[sys.argv.index("--") + 1:][:6]


def install():
    """Install and enable the zip; the add-on's module name."""
    if KIND == "extension":
        repo = next(r for r in bpy.context.preferences.extensions.repos if r.module == "user_default")
        result = bpy.ops.extensions.package_install_files(filepath=ZIP, repo=repo.module, enable_on_install=True)
        module = "bl_ext.%s.radiosity" % repo.module
    else:
        result = bpy.ops.preferences.addon_install(filepath=ZIP, overwrite=True)
        module = "radiosity"
    assert result == {'FINISHED'}, result
    if not addon_utils.check(module)[1]:
        addon_utils.enable(module, default_set=True, handle_error=fail)
    return module


def fail(err):
    raise err


def mapped_libraries():
    """Paths of the shared libraries this process has mapped."""
    with open("/proc/self/maps") as maps:
        return sorted({line.split()[-1] for line in maps if ".so" in line and "/" in line})


def main():
    sys.path.insert(0, SCENES)
    import build_scene
    import scene_kit

    # The scene first: starting an empty file resets the preferences, add-ons included.
    scene = scene_kit.empty_file()
    build_scene.build("cube", scene)
    for material in bpy.data.materials:
        scene_kit.make_lambertian(material)
    reference = rc.render_image(scene, int(REFERENCE_SAMPLES))
    host_libraries = mapped_libraries()   # Blender's own, before the add-on loads
    module = install()
    package = importlib.import_module(module)
    scene.radiosity.quality = float(QUALITY)
    assert bpy.ops.radiosity.solve() == {'FINISHED'}
    np.save(os.path.join(IMAGES, "reference.npy"), reference)
    np.save(os.path.join(IMAGES, "solution.npy"), rc.render_image(scene, 16))
    results = [o for o in scene.objects if o.get("radiosity_result")]
    values = []
    for obj in results:
        attr = obj.data.color_attributes.get("Radiosity")
        if attr is not None:
            rgba = np.empty(4 * len(attr.data), dtype=np.float32)
            attr.data.foreach_get("color", rgba)
            values.append(rgba.reshape(-1, 4)[:, :3])
    values = np.concatenate(values) if values else np.zeros((0, 3))
    native = sys.modules[module + "._radiosity"]
    print("RESULT " + json.dumps({
        "module": module, "addon_file": package.__file__, "module_file": native.__file__,
        "host_libraries": host_libraries, "libraries": mapped_libraries(), "status": scene.radiosity.stats.status,
        "elements": scene.radiosity.stats.elements, "results": len(results),
        "attributes": sum(1 for o in results if "Radiosity" in o.data.color_attributes),
        "finite": bool(np.all(np.isfinite(values))), "max_radiance": float(values.max(initial=0.0)),
        "min_radiance": float(values.min(initial=0.0)),
    }), flush=True)


main()
