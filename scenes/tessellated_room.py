"""`tessellated_room`: a 4 x 3 x 2.5 m room modelled the way a Blender user
models one, with Blender's own operators: the default cube scaled into a room
(scale not applied, normals pointing out), a colour-grid rug 2 mm above the
floor, a smooth-shaded UV sphere (512 faces) resting on the floor, a box
standing on the floor, and Suzanne on the box, mirrored by a negative scale
with a Subdivision Surface modifier (about 2,000 faces, most not planar); a
disk area light 1 cm under the ceiling and a small point light.

What it measures (bench/tessellated_room.py): the cost of finely tessellated
objects, whose many small faces lie close together, against the boxes of the
bundled rooms. `build(scene, objects=..., lights=...)` takes subsets of
OBJECTS and LIGHTS.
"""

import math

import bpy

import scene_kit as kit

OBJECTS = ("rug", "sphere", "box", "monkey")
LIGHTS = ("area", "point")


def _active_with(material):
    obj = bpy.context.object
    obj.data.materials.append(material)
    return obj


def _colour_grid_material():
    """A Diffuse BSDF fed by Blender's generated colour-grid image."""
    mat = kit.lambertian_material("Rug", (1.0, 1.0, 1.0))
    image = bpy.data.images.new("Rug grid", 256, 256)
    image.generated_type = 'COLOR_GRID'
    texture = mat.node_tree.nodes.new("ShaderNodeTexImage")
    texture.image = image
    bsdf = next(n for n in mat.node_tree.nodes if n.type == 'BSDF_DIFFUSE')
    mat.node_tree.links.new(texture.outputs["Color"], bsdf.inputs["Color"])
    return mat


def build(scene, objects=OBJECTS, lights=LIGHTS):
    kit.setup_render(scene)
    bpy.ops.mesh.primitive_cube_add(size=2, location=(0, 0, 1.25))
    room = _active_with(kit.lambertian_material("Walls", (0.7, 0.7, 0.65)))
    room.scale = (2.0, 1.5, 1.25)
    if "rug" in objects:
        bpy.ops.mesh.primitive_plane_add(size=1.6, location=(0.2, 0.4, 0.002))
        _active_with(_colour_grid_material())
    if "sphere" in objects:
        bpy.ops.mesh.primitive_uv_sphere_add(radius=0.35, location=(0.9, 0.5, 0.35))
        bpy.ops.object.shade_smooth()
        _active_with(kit.lambertian_material("Red", (0.7, 0.1, 0.08)))
    if "box" in objects:
        bpy.ops.mesh.primitive_cube_add(size=1, location=(-0.9, 0.6, 0.3))
        _active_with(kit.lambertian_material("Blue", (0.15, 0.25, 0.6))).scale = (0.6, 0.6, 0.6)
    if "monkey" in objects:
        bpy.ops.mesh.primitive_monkey_add(size=0.6, location=(-0.9, 0.6, 0.82),
                                          rotation=(0, 0, math.radians(200)))
        monkey = _active_with(kit.lambertian_material("Gold", (0.8, 0.6, 0.2)))
        monkey.scale = (-1, 1, 1)
        monkey.modifiers.new("Subdivision", 'SUBSURF').levels = 1
    if "area" in lights:
        bpy.ops.object.light_add(type='AREA', location=(0, 0.2, 2.49))
        area = bpy.context.object.data
        area.shape, area.size, area.energy = 'DISK', 0.6, 40.0
    if "point" in lights:
        bpy.ops.object.light_add(type='POINT', location=(1.4, -1.0, 1.8))
        point = bpy.context.object.data
        point.energy, point.shadow_soft_size = 15.0, 0.05
    bpy.ops.object.camera_add(location=(0.3, -1.4, 1.4), rotation=(math.radians(72), 0, math.radians(8)))
    scene.camera = bpy.context.object
    scene.camera.data.lens = 16
    for obj in scene.objects:
        obj.select_set(False)
