"""`dining_room`: a large room lit by one small bright light over a table.

An 8 x 6 x 3 m room with warm walls and a dark floor; a 2 x 1 m table with
four chairs in the middle; a 0.3 m square pendant-like panel, 1.2 m above the
table, very bright, is the only light. The table and chairs are lit directly,
the far corners only by interreflection: a scene with a large dynamic range
and dim corners, where refinement must concentrate near the light.
"""

import full_office
import scene_kit as kit

ROOM_LO, ROOM_HI = (-4.0, -3.0, 0.0), (4.0, 3.0, 3.0)
TABLE_TOP = (2.0, 1.0, 0.05)
TABLE_HEIGHT = 0.75
LIGHT_SIZE = 0.3
LIGHT_HEIGHT = 1.95          # the panel, 1.2 m above the table top
# Radiance of the panel: the same power as the office's panel, from 1/8 of its area.
LIGHT_STRENGTH = 240.0

WALL = (0.7, 0.6, 0.45)
CEILING = (0.8, 0.8, 0.78)
FLOOR = (0.2, 0.12, 0.08)
TABLE = (0.45, 0.25, 0.12)
FABRIC = (0.5, 0.1, 0.08)
METAL = (0.1, 0.1, 0.1)


def build(scene):
    wall = kit.diffuse_material("Wall", WALL)
    materials = {"Floor": kit.diffuse_material("Floor", FLOOR),
                 "Ceiling": kit.diffuse_material("Ceiling", CEILING)}
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI).items():
        kit.add_mesh(scene, name, geometry, materials.get(name, wall))

    wood = kit.diffuse_material("Table", TABLE)
    kit.add_mesh(scene, "Table.Top", kit.box(TABLE_TOP), wood,
                 location=(0.0, 0.0, TABLE_HEIGHT - TABLE_TOP[2] / 2))
    leg_h = TABLE_HEIGHT - TABLE_TOP[2]
    leg = kit.box((0.07, 0.07, leg_h), omit=("top", "bottom"))
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1)), start=1):
        kit.add_mesh(scene, "Table.Leg.%d" % i, leg, wood, location=(sx * 0.9, sy * 0.4, leg_h / 2))

    fabric = kit.diffuse_material("Fabric", FABRIC)
    metal = kit.diffuse_material("Metal", METAL)
    # Two chairs on each long side; add_chair builds one facing +y, so the far
    # side's chairs are that one mirrored in y (rotation about z by 180 degrees).
    for x in (-0.5, 0.5):
        full_office.add_chair(scene, x, -0.75, fabric, metal)
    before = set(scene.objects)
    for x in (-0.5, 0.5):
        full_office.add_chair(scene, -x, -0.75, fabric, metal)
    for obj in set(scene.objects) - before:
        obj.location.x, obj.location.y = -obj.location.x, -obj.location.y
        obj.rotation_euler.z = 3.141592653589793

    # A small bright panel hanging over the table; its back lights the ceiling.
    light = kit.ceiling_light((0.0, 0.0, LIGHT_HEIGHT), LIGHT_SIZE, LIGHT_SIZE)
    kit.add_mesh(scene, "Light", light, kit.emission_material("Light", LIGHT_STRENGTH))

    kit.add_camera(scene, location=(-3.7, -2.7, 2.2), target=(0.5, 0.6, 0.6), lens=16.0)
    kit.setup_render(scene)
