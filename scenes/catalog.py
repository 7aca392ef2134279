"""The bundled scenes, by name. No bpy here: the command-line tools read it too.

Each name is a module in this folder with a `build(scene)` function that fills
an empty Blender scene (see build_scene.py).
"""

SCENES = {
    "cube": "closed cube room, red and green side walls, ceiling light, small cube casting a shadow",
    "office": "5 x 4 x 3 m room, table with four legs under a ceiling light",
}
