"""`cube`: a closed 2 m cube room in the manner of the Cornell box.

Red left wall, green right wall, the other four white; a 0.5 m square light
recessed in the ceiling's centre; a 0.5 m white cube on the floor, turned a
little, casting a soft shadow; the camera inside, against the front wall,
looking at the cube. Shows direct light, shadow and colour bleeding.
"""

import math

import scene_kit as kit

ROOM_LO, ROOM_HI = (-1.0, -1.0, 0.0), (1.0, 1.0, 2.0)
LIGHT_SIZE = 0.5
# Radiance of the light. The room's average radiance is about
# L * A_light / (A_room * (1 - mean reflectance)), so this gives walls of 0.3-0.5
# under the Standard view transform.
LIGHT_STRENGTH = 12.0

WHITE = (0.75, 0.75, 0.75)
RED = (0.63, 0.065, 0.05)
GREEN = (0.14, 0.45, 0.091)


def build(scene):
    white = kit.diffuse_material("White", WHITE)
    red = kit.diffuse_material("Red", RED)
    green = kit.diffuse_material("Green", GREEN)
    colours = {"Wall.Left": red, "Wall.Right": green}
    opening = kit.light_opening((0.0, 0.0), LIGHT_SIZE, LIGHT_SIZE)
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI, opening).items():
        kit.add_mesh(scene, name, geometry, colours.get(name, white))

    # Recessed: flush with the ceiling, in an opening of it, so the two never overlap.
    light = kit.ceiling_light((0.0, 0.0, ROOM_HI[2]), LIGHT_SIZE, LIGHT_SIZE)
    kit.add_mesh(scene, "Light", light, kit.emission_material("Light", LIGHT_STRENGTH))

    # No bottom face: it would lie on the floor, unseen and unlit.
    size = 0.5
    kit.add_mesh(scene, "Cube", kit.box((size, size, size), omit=("bottom",)), white,
                 location=(0.3, 0.05, size / 2), rotation=(0.0, 0.0, math.radians(20)))

    kit.add_camera(scene, location=(0.0, -0.95, 1.2), target=(0.05, 0.4, 0.4), lens=18.0)
    kit.setup_render(scene)
