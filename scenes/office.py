"""`office`: a 5 x 4 x 3 m room with a table under a ceiling light.

White walls and ceiling, a pale blue back wall, a grey-brown floor; a wooden
table (top 1.6 x 0.9 m, 0.76 m high) on four thin legs; a 1.2 x 0.6 m emitting
panel recessed in the ceiling above it; the camera high in a corner looking at the
table and the far walls. Shows the shadow under the table and soft light on
the walls.
"""

import scene_kit as kit

ROOM_LO, ROOM_HI = (-2.5, -2.0, 0.0), (2.5, 2.0, 3.0)
TABLE_CENTER = (0.3, 0.3)
TABLE_TOP = (1.6, 0.9, 0.04)   # size of the top
TABLE_HEIGHT = 0.76            # floor to the top's upper face
LEG = 0.05                     # legs' side
LEG_INSET = 0.08               # from the top's edges to the legs' centres
LIGHT_SIZE = (1.2, 0.6)
# Radiance of the panel, chosen for walls of about 0.3-0.4 under the Standard
# view transform (see cube.py for the estimate).
LIGHT_STRENGTH = 30.0

WALL = (0.7, 0.7, 0.7)
BACK_WALL = (0.35, 0.5, 0.7)
CEILING = (0.8, 0.8, 0.8)
FLOOR = (0.35, 0.3, 0.25)
WOOD = (0.5, 0.3, 0.15)
METAL = (0.1, 0.1, 0.1)


def build(scene):
    materials = {
        "Floor": kit.diffuse_material("Floor", FLOOR),
        "Ceiling": kit.diffuse_material("Ceiling", CEILING),
        "Wall.Back": kit.diffuse_material("Back Wall", BACK_WALL),
    }
    wall = kit.diffuse_material("Wall", WALL)
    opening = kit.light_opening(TABLE_CENTER, *LIGHT_SIZE)
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI, opening).items():
        kit.add_mesh(scene, name, geometry, materials.get(name, wall))

    cx, cy = TABLE_CENTER
    top_w, top_d, top_t = TABLE_TOP
    kit.add_mesh(scene, "Table.Top", kit.box(TABLE_TOP), kit.diffuse_material("Wood", WOOD),
                 location=(cx, cy, TABLE_HEIGHT - top_t / 2))
    # Open tubes: their ends touch the floor and the top, and would be unseen.
    leg_h = TABLE_HEIGHT - top_t
    leg = kit.box((LEG, LEG, leg_h), omit=("top", "bottom"))
    metal = kit.diffuse_material("Metal", METAL)
    dx, dy = top_w / 2 - LEG_INSET, top_d / 2 - LEG_INSET
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1)), start=1):
        kit.add_mesh(scene, "Table.Leg.%d" % i, leg, metal,
                     location=(cx + sx * dx, cy + sy * dy, leg_h / 2))

    # Recessed in an opening of the ceiling, flush with it.
    light = kit.ceiling_light((cx, cy, ROOM_HI[2]), *LIGHT_SIZE)
    kit.add_mesh(scene, "Light", light, kit.emission_material("Light", LIGHT_STRENGTH))

    kit.add_camera(scene, location=(-2.3, -1.8, 1.7), target=(0.6, 0.9, 0.95), lens=18.0)
    kit.setup_render(scene)
