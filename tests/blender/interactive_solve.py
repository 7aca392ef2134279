"""Blender side of test_interactive.py: the interactive solve in a real window.

    xvfb-run blender --factory-startup --enable-event-simulate FILE.blend \
        --python interactive_solve.py -- ADDON_DIR run|cancel

Invokes radiosity.solve with INVOKE_DEFAULT in the 3D view (worker thread,
modal timer, progress), optionally sends ESC through the window's event
queue, waits for the bake and prints one line "RESULT <json>" before quitting.
"""

import json
import sys
import time

import addon_utils
import bpy

ADDON, MODE = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, ADDON)


def fail(err):
    raise err


addon_utils.enable("radiosity", default_set=False, handle_error=fail)
from radiosity import operators  # noqa: E402  (the add-on, enabled above)
state = {"start": None, "invoke": None, "progress_seen": False}


def window():
    return bpy.context.window_manager.windows[0]


def start():
    win = window()
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    bpy.context.scene.radiosity.quality = 1.0 if MODE == "cancel" else 0.5
    with bpy.context.temp_override(window=win, area=area):
        state["invoke"] = sorted(bpy.ops.radiosity.solve('INVOKE_DEFAULT'))
    state["start"] = time.time()


def first_pass_done():
    progress = operators.running_progress()
    return bool(progress) and (progress.get("phase") == "pass" or progress.get("pass", 0) >= 1)


def escape():
    # After the first complete pass, however loaded the machine (a fixed delay
    # failed when the machine was busy), and before the solve at quality 1 ends.
    if state["start"] is None or not first_pass_done():
        return 0.05
    window().event_simulate(type='ESC', value='PRESS')
    return None


def check():
    if state["start"] is None:
        return 0.2
    stats = bpy.context.scene.radiosity.stats
    if not stats.valid and time.time() - state["start"] < 120:
        return 0.2
    results = [o for o in bpy.context.scene.objects if o.get("radiosity_result")]
    shading = [s.shading.color_type for a in window().screen.areas for s in a.spaces if s.type == 'VIEW_3D']
    print("RESULT " + json.dumps({
        "invoke": state["invoke"], "valid": stats.valid, "status": stats.status,
        "elements": stats.elements, "results": len(results), "shading": shading,
        "hidden": all(o.hide_render for o in bpy.context.scene.objects
                      if o.type == 'MESH' and not o.get("radiosity_result")),
    }), flush=True)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(start, first_interval=1.0)
if MODE == "cancel":
    bpy.app.timers.register(escape, first_interval=1.2)
bpy.app.timers.register(check, first_interval=1.5)
