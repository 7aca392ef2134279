"""Imports a scene of catalog.py into Blender as a user would light it, and
saves it as <build>/furnished/<name>.blend (runs inside Blender):

    blender -b --factory-startup --python bench/furnished/import_scene.py -- [--build build] [--preview] [NAME ...]

For each scene (all without names): fetch it (catalog.prepare: cached and
checksum-verified), import it into an empty file with Blender's own importer
(glTF: import_scene.gltf; OBJ: wm.obj_import where it exists, else
import_scene.obj; PLY: wm.ply_import or import_mesh.ply), bring it to metres
and Z up, keep what lights it brings and, where it brings none, add what the
RECIPES below say (ceiling panels, a sky opening, a sun), add a camera inside
looking at the furnished part, and save. The triangles Blender counts after
import (loop triangles of every mesh) are printed and written to
<build>/furnished/imported.json. --preview also renders a 32-sample Cycles
image of each to <build>/furnished/<name>_preview.png, to check the camera.
"""

import argparse
import json
import math
import pathlib
import sys

import bpy
from mathutils import Matrix, Vector

HERE = pathlib.Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import catalog  # noqa: E402

RESOLUTION = (320, 240)


def panel(name, location, size, power, shape='SQUARE', size_y=None):
    """An area light facing down (-Z), as a ceiling panel."""
    light = bpy.data.lights.new(name, 'AREA')
    light.shape = shape
    light.size = size
    if size_y is not None:
        light.size_y = size_y
    light.energy = power
    obj = bpy.data.objects.new(name, light)
    obj.location = location
    bpy.context.scene.collection.objects.link(obj)
    return obj


def sun(name, elevation, azimuth, strength, angle=0.0093):
    light = bpy.data.lights.new(name, 'SUN')
    light.energy = strength
    light.angle = angle
    obj = bpy.data.objects.new(name, light)
    # A sun shines along its -Z: tilt it down from the zenith to the elevation.
    obj.rotation_euler = (math.radians(90.0 - elevation), 0.0, math.radians(azimuth))
    bpy.context.scene.collection.objects.link(obj)
    return obj


def world(colour, strength=1.0):
    w = bpy.data.worlds.new("World")
    w.use_nodes = True
    background = w.node_tree.nodes["Background"]
    background.inputs["Color"].default_value = (*colour, 1.0)
    background.inputs["Strength"].default_value = strength
    bpy.context.scene.world = w


def camera(location, target, lens=18.0):
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.data.lens = lens
    cam.data.clip_start = 0.05
    cam.data.clip_end = 500.0
    cam.location = location
    direction = Vector(target) - Vector(location)
    cam.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
    bpy.context.scene.collection.objects.link(cam)
    bpy.context.scene.camera = cam
    return cam


def light_fzk_haus():
    """Ground floor: the rooms' ceilings are at 2.50 m (slab 2.50-2.70); one 1 m
    ceiling panel 2 cm under each room's ceiling, 60 W (a bright room light).
    The attic (2.70 m to the ridge at 6.3 m) gets one panel under the ridge."""
    rooms = {"Kitchen": (2.0, 2.1), "Living": (9.6, 2.1), "Dining": (5.6, 2.4), "Hall": (2.0, 5.0),
             "Office": (2.0, 7.9), "Bath": (5.7, 7.9), "Bedroom": (9.6, 7.0)}
    for room, (x, y) in rooms.items():
        panel("Ceiling " + room, (x, y, 2.48), 1.0, 60.0)
    panel("Attic", (6.0, 5.0, 5.6), 1.0, 60.0)
    world((0.0, 0.0, 0.0))
    # The living room: the fireplace, the armchair and the spiral stair behind.
    camera((11.3, 0.7, 1.6), (7.6, 3.6, 0.8), lens=16.0)


def light_sponza():
    """The atrium is open to the sky between the roofs of its galleries: one area
    light filling that opening just under the roofline, facing down, 4 kW over
    its 24 x 7 m (an overcast sky). World black, so that the opening is the only light."""
    panel("Sky opening", (-0.6, 0.0, 12.8), 24.0, 4000.0, shape='RECTANGLE', size_y=7.0)
    world((0.0, 0.0, 0.0))
    # Down the atrium's length from the ground floor, the arcades on both sides.
    camera((-12.0, 0.8, 1.8), (6.0, -0.6, 4.5), lens=16.0)


def light_samurai_monastery():
    """An open temple precinct: a sun 40 degrees high and a uniform grey sky."""
    sun("Sun", 40.0, 35.0, 3.0)
    world((0.35, 0.4, 0.5), 0.6)
    camera((-55.0, -50.0, 22.0), (0.0, 0.0, 4.0), lens=24.0)


RECIPES = {"fzk_haus": light_fzk_haus, "sponza": light_sponza, "samurai_monastery": light_samurai_monastery}


def import_file(path, fmt):
    if fmt in ("glb", "gltf"):
        # Debian's Blender 3.4 glTF importer uses numpy.bool, which numpy 1.24 removed.
        import numpy
        if "bool" not in numpy.__dict__:
            numpy.bool = numpy.bool_
        bpy.ops.import_scene.gltf(filepath=str(path))
    elif fmt == "obj":
        if hasattr(bpy.ops.wm, "obj_import"):
            bpy.ops.wm.obj_import(filepath=str(path), forward_axis='NEGATIVE_Z', up_axis='Y')
        else:
            bpy.ops.import_scene.obj(filepath=str(path), axis_forward='-Z', axis_up='Y')
    elif fmt == "ply":
        if hasattr(bpy.ops.wm, "ply_import"):
            bpy.ops.wm.ply_import(filepath=str(path))
        else:
            bpy.ops.import_mesh.ply(filepath=str(path))
    else:
        raise ValueError(fmt)


def to_metres(scale):
    """Bakes the scale into the meshes, so that objects keep unit scale as a user's would."""
    if scale == 1.0:
        return
    matrix = Matrix.Scale(scale, 4)
    for obj in bpy.context.scene.objects:
        if obj.parent is None:
            obj.matrix_world = matrix @ obj.matrix_world
    bpy.context.view_layer.update()
    meshes = [o for o in bpy.context.scene.objects if o.type == 'MESH']
    for obj in meshes:
        world_matrix = obj.matrix_world.copy()
        obj.parent = None
        obj.data.transform(world_matrix)
        obj.matrix_world = Matrix.Identity(4)


def drop_missing_images():
    """Image textures without pixels render magenta in Cycles; an importer that made
    one for a texture the archive does not ship gets it unlinked (the colour stays)."""
    dropped = 0
    for material in bpy.data.materials:
        if not material.use_nodes:
            continue
        for node in list(material.node_tree.nodes):
            if node.type == 'TEX_IMAGE' and (node.image is None or node.image.size[0] == 0):
                material.node_tree.nodes.remove(node)
                dropped += 1
    return dropped


def count_triangles(scene):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    total = 0
    for obj in scene.objects:
        if obj.type == 'MESH':
            mesh = obj.evaluated_get(depsgraph).data
            mesh.calc_loop_triangles()
            total += len(mesh.loop_triangles)
    return total


def build(name, build_dir, preview=False):
    path, entry = catalog.prepare(name, build_dir)
    bpy.ops.wm.read_factory_settings(use_empty=True)
    scene = bpy.context.scene
    import_file(path, entry.fmt)
    to_metres(entry.scale)
    for obj in scene.objects:
        if obj.type == 'MESH':
            obj.data.validate()   # the samurai OBJ has faces of two corners, which crash loop triangles
    dropped = drop_missing_images()
    brought = [o.name for o in scene.objects if o.type == 'LIGHT']
    emissive = [m.name for m in bpy.data.materials if m.use_nodes and any(
        n.type == 'EMISSION' or (n.type == 'BSDF_PRINCIPLED' and n.inputs.get("Emission Strength") is not None
                                 and n.inputs["Emission Strength"].default_value > 0
                                 and any(n.inputs[k].default_value[:3] != (0, 0, 0) for k in ("Emission", "Emission Color")
                                         if k in n.inputs))
        for n in material_nodes(m))]
    if not brought and not emissive:
        RECIPES[name]()
    scene.render.engine = 'CYCLES'
    scene.render.resolution_x, scene.render.resolution_y = RESOLUTION
    scene.render.resolution_percentage = 100
    triangles = count_triangles(scene)
    out = catalog.furnished_dir(build_dir)
    blend = out / (name + ".blend")
    bpy.ops.wm.save_as_mainfile(filepath=str(blend))
    info = dict(triangles=triangles, objects=sum(o.type == 'MESH' for o in scene.objects),
                lights_brought=brought, emissive_materials=emissive,
                lights_added=[o.name for o in scene.objects if o.type == 'LIGHT' and o.name not in brought],
                missing_images_dropped=dropped, blend=str(blend), blender=bpy.app.version_string)
    record = out / "imported.json"
    known = json.loads(record.read_text()) if record.exists() else {}
    known[name] = info
    record.write_text(json.dumps(known, indent=1))
    print("[import] %s: %s triangles in %d objects; lights brought %d, emissive materials %d, added %d -> %s"
          % (name, format(triangles, ","), info["objects"], len(brought), len(emissive), len(info["lights_added"]),
             blend), flush=True)
    if preview:
        scene.cycles.samples = 32
        scene.cycles.use_denoising = False
        scene.cycles.device = 'CPU'
        scene.render.filepath = str(out / (name + "_preview.png"))
        scene.render.image_settings.file_format = 'PNG'
        bpy.ops.render.render(write_still=True)
    return info


def material_nodes(material):
    return material.node_tree.nodes if material.node_tree else []


def main():
    parser = argparse.ArgumentParser(prog="import_scene.py")
    parser.add_argument("--build", default=str(catalog.ROOT / "build"))
    parser.add_argument("--preview", action="store_true", help="also render a 32-sample preview PNG")
    parser.add_argument("names", nargs="*")
    argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
    args = parser.parse_args(argv)
    for name in args.names or catalog.SCENES:
        build(name, args.build, args.preview)


if __name__ == "__main__":
    main()
