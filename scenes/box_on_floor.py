"""`box_on_floor`: a box standing on the floor, its bottom face lying on it, under
a rectangular area light, in a closed 3 x 3 x 2.5 m room (issue 12).

Built the way a user would: a six-faced box (Blender's cube, scaled) moved down
until it touches the floor, so its bottom face and the floor under it coincide;
a Blender area light (one-sided, pointing down) above it, off to one side so
the box casts a shadow towards the camera. The light is out of the camera's
view (an area light's conversion is checked in tests/blender/test_cycles.py).
"""

import math

import bpy

import scene_kit as kit

ROOM_LO, ROOM_HI = (-1.5, -1.5, 0.0), (1.5, 1.5, 2.5)
BOX_SIZE = 0.6
LIGHT_SIZE = (0.8, 0.5)
LIGHT_HEIGHT = 2.2
# Watts: radiance P / (4 A) = 15 in Blender 3.x, walls at about 0.2-0.5.
LIGHT_POWER = 24.0


def build(scene):
    white = kit.lambertian_material("White", (0.7, 0.7, 0.7))
    blue = kit.lambertian_material("Blue", (0.15, 0.25, 0.55))
    floor = kit.lambertian_material("Floor", (0.45, 0.42, 0.38))
    box = kit.lambertian_material("Box", (0.7, 0.55, 0.3))
    mats = {"Wall.Left": blue, "Floor": floor}
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI).items():
        kit.add_mesh(scene, name, geometry, mats.get(name, white))
    # All six faces: the bottom one lies on the floor (z = 0).
    kit.add_mesh(scene, "Box", kit.box((BOX_SIZE,) * 3), box, location=(0.25, 0.35, BOX_SIZE / 2),
                 rotation=(0.0, 0.0, math.radians(25)))

    light = bpy.data.lights.new("Area", 'AREA')
    light.shape = 'RECTANGLE'
    light.size, light.size_y = LIGHT_SIZE
    light.energy = LIGHT_POWER
    obj = bpy.data.objects.new("Area", light)
    obj.location = (0.6, 0.7, LIGHT_HEIGHT)   # pointing down (-z), the default
    scene.collection.objects.link(obj)

    kit.add_camera(scene, location=(-0.55, -0.95, 1.15), target=(0.25, 0.35, 0.35), lens=18.0)
    kit.setup_render(scene, resolution=(512, 512))
