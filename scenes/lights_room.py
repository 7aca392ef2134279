"""`lights_room`: a 4 x 3 x 2.6 m room with a window, lit the ways Blender users
light rooms (issue 15): a point light under the ceiling, a spot light with a
soft edge on a box, the sun through the window, and the world's colour through
the window. `build(scene, lights=...)` takes a subset of LIGHTS (all by
default) so each can be checked against Cycles alone and together.

Lambertian materials; the window is an opening in the left wall, behind the
camera's field of view, so what the camera sees is light on surfaces.
"""

import math

import bpy
from mathutils import Vector

import scene_kit as kit

ROOM_LO, ROOM_HI = (-2.0, -1.5, 0.0), (2.0, 1.5, 2.6)
WINDOW = ((-0.6, 1.0), (0.6, 2.0))   # (y0, z0), (y1, z1) in the left wall
LIGHTS = ("point", "spot", "sun", "world")
SUN_DIRECTION = (0.72, 0.12, -0.68)  # the way its light travels: down into the room


def left_wall_with_window(lo, hi, window):
    """(vertices, quads) of the left wall (x = lo[0], facing +x) around a window."""
    (x, y0, z0), (_, y1, z1) = lo, hi
    (wy0, wz0), (wy1, wz1) = window
    pieces = [((y0, z0), (y1, wz0)), ((y0, wz1), (y1, z1)), ((y0, wz0), (wy0, wz1)), ((wy1, wz0), (y1, wz1))]
    verts, quads = [], []
    for (a0, b0), (a1, b1) in pieces:
        n = len(verts)
        verts += [(x, a0, b0), (x, a1, b0), (x, a1, b1), (x, a0, b1)]  # normal +x
        quads.append((n, n + 1, n + 2, n + 3))
    import numpy as np
    return np.array(verts, dtype=float), np.array(quads)


def add_light(scene, name, kind, location, target=None, direction=None, **settings):
    light = bpy.data.lights.new(name, kind)
    for key, value in settings.items():
        setattr(light, key, value)
    obj = bpy.data.objects.new(name, light)
    obj.location = location
    aim = Vector(direction) if direction is not None else Vector(target) - Vector(location)
    obj.rotation_euler = aim.to_track_quat('-Z', 'Y').to_euler()
    scene.collection.objects.link(obj)
    return obj


def build(scene, lights=LIGHTS):
    white = kit.lambertian_material("White", (0.7, 0.7, 0.7))
    floor = kit.lambertian_material("Floor", (0.5, 0.42, 0.35))
    blue = kit.lambertian_material("Blue", (0.2, 0.3, 0.6))
    box = kit.lambertian_material("Box", (0.75, 0.6, 0.3))
    walls = kit.room_walls(ROOM_LO, ROOM_HI)
    walls["Wall.Left"] = left_wall_with_window(ROOM_LO, ROOM_HI, WINDOW)
    mats = {"Floor": floor, "Wall.Back": blue}
    for name, geometry in walls.items():
        kit.add_mesh(scene, name, geometry, mats.get(name, white))
    kit.add_mesh(scene, "Box", kit.box((0.6, 0.6, 0.6)), box, location=(0.7, 0.4, 0.3),
                 rotation=(0.0, 0.0, math.radians(20)))

    if "point" in lights:
        add_light(scene, "Point", 'POINT', (-0.6, -0.4, 2.2), target=(-0.6, -0.4, 0.0),
                  energy=120.0, shadow_soft_size=0.08)
    if "spot" in lights:
        add_light(scene, "Spot", 'SPOT', (1.7, -1.2, 2.3), target=(0.7, 0.4, 0.0), energy=400.0,
                  shadow_soft_size=0.05, spot_size=math.radians(45), spot_blend=0.4)
    if "sun" in lights:
        add_light(scene, "Sun", 'SUN', (-3.0, 0.0, 3.0), direction=SUN_DIRECTION, energy=4.0,
                  angle=math.radians(1.0))

    kit.add_camera(scene, location=(-1.75, -1.3, 1.7), target=(0.9, 0.6, 0.3), lens=16.0)
    kit.setup_render(scene, resolution=(512, 512))
    if "world" in lights:
        scene.world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.35, 0.45, 0.7, 1.0)
        scene.world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.5
