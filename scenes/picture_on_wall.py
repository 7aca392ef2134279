"""`picture_on_wall`: a picture (a thin coloured quad) hanging 1 mm in front of
the back wall of a closed 3 x 3 x 2.5 m room lit by a ceiling light (issue 12).

The light is recessed (flush in an opening of the ceiling, as in the bundled
scenes), so the picture is the scene's only near-contact: the wall behind it
is reached by light only through the 1 mm slit around its edges.
"""

import scene_kit as kit

ROOM_LO, ROOM_HI = (-1.5, -1.5, 0.0), (1.5, 1.5, 2.5)
LIGHT_SIZE = 0.6
LIGHT_AT = (0.0, 0.3)
# Radiance of the light: walls at about 0.2-0.5 under the Standard view transform.
LIGHT_STRENGTH = 14.0
PICTURE_SIZE = (0.9, 0.6)
PICTURE_CENTRE = (0.1, 1.35)   # x, z on the back wall
PICTURE_GAP = 1e-3              # metres in front of the wall


def build(scene):
    white = kit.lambertian_material("White", (0.7, 0.7, 0.7))
    floor = kit.lambertian_material("Floor", (0.45, 0.42, 0.38))
    picture = kit.lambertian_material("Picture", (0.6, 0.15, 0.1))
    opening = kit.light_opening(LIGHT_AT, LIGHT_SIZE, LIGHT_SIZE)
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI, opening).items():
        kit.add_mesh(scene, name, geometry, floor if name == "Floor" else white)
    light = kit.ceiling_light((*LIGHT_AT, ROOM_HI[2]), LIGHT_SIZE, LIGHT_SIZE)
    kit.add_mesh(scene, "Light", light, kit.emission_material("Light", LIGHT_STRENGTH))

    w, h = PICTURE_SIZE
    cx, cz = PICTURE_CENTRE
    y = ROOM_HI[1] - PICTURE_GAP
    # Normal -y: facing into the room, its back 1 mm from the wall.
    kit.add_mesh(scene, "Picture", kit.quad((cx - w / 2, y, cz - h / 2), (w, 0, 0), (0, 0, h)), picture)

    kit.add_camera(scene, location=(-0.35, -0.2, 1.45), target=(0.1, 1.5, 1.25), lens=20.0)
    kit.setup_render(scene, resolution=(512, 512))
