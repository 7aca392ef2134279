"""Blender side of test_interactive.py's viewport check: a solved scene as a
user sees it in Solid view.

    xvfb-run blender --factory-startup FILE.blend --python viewport_screenshot.py -- \
        ADDON_DIR OUT.png cull|nocull

Solves the scene (the operator's synchronous path, in the window's 3D view,
with "View Result" on), looks through the scene camera, optionally turns the
back-face culling that View Result sets off again, and saves a screenshot of
the 3D view to OUT.png before quitting.
"""

import sys

import addon_utils
import bpy

ADDON, OUT, MODE = sys.argv[sys.argv.index("--") + 1:][:3]
sys.path.insert(0, ADDON)


def fail(err):
    raise err


addon_utils.enable("radiosity", default_set=False, handle_error=fail)


def view3d():
    win = bpy.context.window_manager.windows[0]
    return win, next(a for a in win.screen.areas if a.type == 'VIEW_3D')


def solve():
    win, area = view3d()
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.radiosity.solve()
    space = area.spaces[0]
    space.region_3d.view_perspective = 'CAMERA'
    if MODE == "nocull":
        space.shading.show_backface_culling = False
    bpy.app.timers.register(shoot, first_interval=1.0)  # after a redraw


def shoot():
    win, area = view3d()
    with bpy.context.temp_override(window=win, area=area):
        bpy.ops.screen.screenshot_area(filepath=OUT)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(solve, first_interval=0.5)
