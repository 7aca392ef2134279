"""Blender side of test_interactive.py: the interactive solve in a real window.

    xvfb-run blender --factory-startup --enable-event-simulate FILE.blend \
        --python interactive_solve.py -- ADDON_DIR run|cancel|cancel_after:SECONDS

Invokes radiosity.solve with INVOKE_DEFAULT in the 3D view (worker thread,
modal timer, progress), optionally sends ESC through the window's event
queue (after the first pass, or SECONDS after the click), waits for the bake
and prints one line "RESULT <json>" before quitting. While the solve runs a
timer watches it as a user would: the progress it reports, how often a UI
timer gets to run, and the result meshes changing pass by pass.
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
state = {"start": None, "invoke": None, "progress_seen": False, "fractions": [], "last_progress": None,
         "ticks": 0, "running_seconds": 0.0, "mesh_states": [], "updates_while_running": 0}


def window():
    return bpy.context.window_manager.windows[0]


def start():
    win = window()
    area = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    bpy.context.scene.radiosity.quality = 1.0 if MODE.startswith("cancel") else 0.5
    with bpy.context.temp_override(window=win, area=area):
        state["invoke"] = sorted(bpy.ops.radiosity.solve('INVOKE_DEFAULT'))
    state["start"] = time.time()


def first_pass_done():
    progress = operators.running_progress()
    return bool(progress) and (progress.get("phase") == "pass" or progress.get("pass", 0) >= 1)


def result_polygons():
    return sum(len(o.data.polygons) for o in bpy.context.scene.objects
               if o.get("radiosity_result") and o.type == 'MESH')


def watch():
    # A UI timer at 20 Hz: how often it runs while the solve runs says how
    # responsive the interface stays; the result meshes it sees change are
    # the passes shown live.
    if state["start"] is None:
        return 0.05
    progress = operators.running_progress()
    if progress is None and state["ticks"] > 0:
        return None  # the solve has ended
    if progress is not None:
        state["ticks"] += 1
        state["running_seconds"] = time.time() - state["start"]
        if "fraction" in progress:
            state["fractions"].append(progress["fraction"])
            state["last_progress"] = progress
        polygons = result_polygons()
        if polygons and (not state["mesh_states"] or state["mesh_states"][-1] != polygons):
            state["mesh_states"].append(polygons)
            state["updates_while_running"] += 1
    return 0.05


def escape_after(seconds):
    def escape_now():
        if state["start"] is None or time.time() - state["start"] < seconds:
            return 0.02
        window().event_simulate(type='ESC', value='PRESS')
        state["escaped_at"] = time.time() - state["start"]
        return None
    return escape_now


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
        "fractions": state["fractions"], "last_progress": state["last_progress"],
        "timer_hz": state["ticks"] / max(state["running_seconds"], 1e-9),
        "running_seconds": state["running_seconds"], "updates_while_running": state["updates_while_running"],
        "final_polygons": result_polygons(), "escaped_at": state.get("escaped_at"),
    }), flush=True)
    bpy.ops.wm.quit_blender()
    return None


bpy.app.timers.register(start, first_interval=1.0)
bpy.app.timers.register(watch, first_interval=1.05)
if MODE == "cancel":
    bpy.app.timers.register(escape, first_interval=1.2)
elif MODE.startswith("cancel_after:"):
    bpy.app.timers.register(escape_after(float(MODE.split(":")[1])), first_interval=1.02)
bpy.app.timers.register(check, first_interval=1.5)
