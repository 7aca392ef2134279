"""The bundled scenes, by name. No bpy here: the command-line tools read it too.

Each name is a module in this folder with a `build(scene)` function that fills
an empty Blender scene (see build_scene.py).
"""

SCENES = {
    "cube": "closed cube room, red and green side walls, ceiling light, small cube casting a shadow",
    "office": "5 x 4 x 3 m room, table with four legs under a ceiling light",
    "full_office": "the office plus a chair, shelves and a cabinet: high occlusion",
    "dining_room": "8 x 6 x 3 m room, one small bright light over a table with chairs, dim corners",
    "cornell_box": "the Cornell box as published (Lambertian), its light 0.1 mm under the ceiling, open front",
    "gradient_large_45": "Section 4.3.1 Fig. 22: occluder at 45 degrees, large emitter",
    "gradient_small_45": "Section 4.3.1 Fig. 23: occluder at 45 degrees, small emitter",
    "gradient_large_aligned": "Section 4.3.1 Fig. 24: occluder aligned, large emitter",
    "gradient_small_aligned": "Section 4.3.1 Fig. 25: occluder aligned, small emitter",
}

# Closed rooms (walls, floor, ceiling), as opposed to the open Section 4.3.1 set-ups
# and the Cornell box (open at the front, as published).
ROOMS = ("cube", "office", "full_office", "dining_room")

# Scenes of contact and near-contact geometry (issue 12), built the way users
# build them; the Cycles agreement tests (tests/blender/test_contact.py) and
# bench/contact_gap.py use them with the Cornell box. Not in SCENES: they are
# not rooms with one downward light like the bundled scenes.
CONTACT_SCENES = {
    "box_on_floor": "3 x 3 x 2.5 m room, a box standing on the floor (its bottom face on it) under an area light",
    "lamp_on_table": "3 x 3 x 2.5 m room lit only by an emissive plane lying on a table top",
    "picture_on_wall": "3 x 3 x 2.5 m room with a recessed ceiling light, a picture 1 mm in front of a wall",
}

# Scenes lit the ways Blender users light them (issue 15): point, spot and sun
# lights and the world's colour; tests/blender/test_lights.py checks them
# against Cycles.
LIGHT_SCENES = {
    "lights_room": "4 x 3 x 2.6 m room with a window: a point light, a soft-edged spot, the sun and the "
                   "world through the window (build(scene, lights=...) takes a subset)",
}

# A room of finely tessellated objects modelled with Blender's operators (a UV
# sphere, a subdivided Suzanne): what many small faces close together cost
# (bench/tessellated_room.py). Not in SCENES: minutes to solve.
TESSELLATED_SCENES = {
    "tessellated_room": "4 x 3 x 2.5 m room from the default cube: a textured rug, a UV sphere, a box, a subdivided "
                        "Suzanne; a disk light under the ceiling and a point light",
}
