"""`lamp_on_table`: a closed 3 x 3 x 2.5 m room lit only by an emissive plane
lying flat on a table top (issue 12), like a light pad put down on a desk.

The plane is a mesh with an Emission shader, so it emits from both sides (as
Cycles renders it): its top lights the room, its bottom the table top under
it, which nothing else sees. It lies on the table to the eye, 0.1 mm above its
top: exactly coplanar faces z-fight in Cycles (a ray picks either), which
would leave the path-traced reference undefined. The table is a solid block
standing on the floor (no bottom face, so the only contact is the lamp's).
"""

import scene_kit as kit

ROOM_LO, ROOM_HI = (-1.5, -1.5, 0.0), (1.5, 1.5, 2.5)
TABLE_SIZE = (1.2, 0.7, 0.75)
TABLE_AT = (0.2, 0.3)
LAMP_SIZE = (0.4, 0.3)
LIFT = 1e-4   # metres between the table top and the lamp
# Radiance of the lamp: the walls and ceiling render at about 0.1-0.5.
LAMP_STRENGTH = 60.0


def build(scene):
    white = kit.lambertian_material("White", (0.7, 0.7, 0.7))
    floor = kit.lambertian_material("Floor", (0.45, 0.42, 0.38))
    green = kit.lambertian_material("Green", (0.2, 0.45, 0.25))
    wood = kit.lambertian_material("Table", (0.55, 0.35, 0.2))
    mats = {"Wall.Right": green, "Floor": floor}
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI).items():
        kit.add_mesh(scene, name, geometry, mats.get(name, white))
    w, d, h = TABLE_SIZE
    kit.add_mesh(scene, "Table", kit.box(TABLE_SIZE, omit=("bottom",)), wood, location=(*TABLE_AT, h / 2))

    lx, ly = LAMP_SIZE
    x0, y0 = TABLE_AT[0] - 0.2 - lx / 2, TABLE_AT[1] - ly / 2
    # Normal up (+z): the side a user sees from above.
    kit.add_mesh(scene, "Lamp", kit.quad((x0, y0, h + LIFT), (lx, 0, 0), (0, ly, 0)),
                 kit.emission_material("Lamp", LAMP_STRENGTH))

    kit.add_camera(scene, location=(-0.65, -0.95, 1.55), target=(0.05, 0.35, 0.7), lens=18.0)
    kit.setup_render(scene, resolution=(512, 512))
