"""Blender side of test_interactive.py: the interactive solve in a real window.

    xvfb-run blender --factory-startup FILE.blend \
        --python interactive_solve.py -- ADDON_DIR MODE [SHOTS_DIR]

MODE: run, cancel, cancel_after:SECONDS, clicks, menu_undo or edit_mode.

Once the window is idle (its first draws compile shaders, seconds of CPU under
software OpenGL), invokes radiosity.solve with INVOKE_DEFAULT in the 3D view
(worker thread, modal timer, progress), optionally presses Esc on the X
display with xdotool (after the first pass, or SECONDS after the click), waits
for the bake and prints one line "RESULT <json>" before quitting. While the
solve runs a timer watches it as a user would: the progress it reports, how
often a UI timer gets to run, the result meshes changing pass by pass, and
the elements refined 2, 4 and 6 s after the click. "clicks": once a pass is
shown, real events on the X display as a user would send them: Ctrl+Z (which
must wait: the solve's undo lock), then Z's pie menu in the 3D view and a click
on its Material Preview; when the view's shading reads Material Preview while
the solve still runs, Esc. "menu_undo": once a pass is shown, Edit > Undo's
operator run as its menu item runs it (no key: keys of Undo wait). "edit_mode":
an object the solve leaves out (disabled in renders) goes into Edit Mode right
after the click, as the header's mode menu would, and back to Object Mode once
the solver has finished. With SHOTS_DIR it writes
SHOTS_DIR/solve_in_progress.png, the window when the first pass is shown
(the Properties editor scrolled to the Radiosity panel).

Not --enable-event-simulate: with it Blender polls for events without ever
sleeping, and that busy main thread took a core from the solve. The
viewport's anti-aliasing is off: under the software OpenGL of a virtual
display each of its 8 samples is a full CPU render of the view (about 0.2 s
for a furnished room) on the cores the solve needs, where a GPU would take
nothing; the add-on's own pacing (live_pacing.py) bounds what is left.
"""

import json
import os
import subprocess
import sys
import time

import addon_utils
import bpy

ARGS = sys.argv[sys.argv.index("--") + 1:]
ADDON, MODE = ARGS[:2]
SHOTS = ARGS[2] if len(ARGS) > 2 else None
sys.path.insert(0, ADDON)


def fail(err):
    raise err


addon_utils.enable("radiosity", default_set=False, handle_error=fail)
from radiosity.ui import operators  # noqa: E402  (the add-on, enabled above)
bpy.context.preferences.system.viewport_aa = 'OFF'  # see above; --factory-startup saves no preferences
state = {"start": None, "invoke": None, "fractions": [], "last_progress": None,
         "ticks": 0, "running_seconds": 0.0, "mesh_states": [], "updates_while_running": 0,
         "leaves_after": {}, "clicks": None}
MARKS = (2.0, 4.0, 6.0)  # seconds after the click at which the refined elements are noted


def window():
    return bpy.context.window_manager.windows[0]


def properties_area():
    return next(a for a in window().screen.areas if a.type == 'PROPERTIES')


def show_render_tab():
    properties_area().spaces.active.context = 'RENDER'


def show_the_panel():
    """The Properties editor (on the Render tab since it last drew) scrolled to
    the Radiosity panel, at its end."""
    win, area = window(), properties_area()
    region = next(r for r in area.regions if r.type == 'WINDOW')
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region):
        for _ in range(100):
            bpy.ops.view2d.scroll_down()
        for _ in range(5):  # back up to the Solve button and its progress bar
            bpy.ops.view2d.scroll_up()


def screenshot_in_progress():
    win = window()
    with bpy.context.temp_override(window=win, screen=win.screen, area=win.screen.areas[0]):
        bpy.ops.screen.screenshot(filepath=os.path.join(SHOTS, "solve_in_progress.png"))
    state["screenshot_at"] = time.time() - state["start"]


def view_3d():
    return next(a for a in window().screen.areas if a.type == 'VIEW_3D')


def start():
    win = window()
    area = view_3d()
    bpy.context.scene.radiosity.quality = 1.0 if MODE.startswith("cancel") or MODE == "clicks" else 0.5
    if MODE == "edit_mode":
        mesh = bpy.data.meshes.new("Edited")
        mesh.from_pydata([(0, 0, 5), (1, 0, 5), (1, 1, 5)], [], [(0, 1, 2)])
        edited = bpy.data.objects.new("Edited", mesh)
        edited.hide_render = True  # left out of the solve, so it stays shown and editable
        bpy.context.scene.collection.objects.link(edited)
        bpy.context.view_layer.objects.active = edited
    if MODE in ("clicks", "menu_undo"):
        # An undo step to go back to (the file as loaded has none): Ctrl+Z, if it
        # were not locked, would take the scene back to quality 0.5, without the pass.
        bpy.ops.ed.undo_push(message="Radiosity quality 1")
    with bpy.context.temp_override(window=win, area=area):
        state["invoke"] = sorted(bpy.ops.radiosity.solve('INVOKE_DEFAULT'))
    state["start"] = time.time()
    if MODE == "edit_mode":
        # Before the operator's first timer tick: whatever the machine's speed, the
        # whole solve runs with an object in Edit Mode.
        state["edit_mode"] = {"enter": in_view_3d(bpy.ops.object.mode_set, mode='EDIT'), "mode": bpy.context.mode}


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
        state["ended"] = True
        return None  # the solve has ended
    if progress is not None:
        state["ticks"] += 1
        state["running_seconds"] = time.time() - state["start"]
        for mark in MARKS:
            if state["running_seconds"] >= mark and str(mark) not in state["leaves_after"]:
                state["leaves_after"][str(mark)] = progress.get("leaves", 0)
        if "fraction" in progress:
            state["fractions"].append(progress["fraction"])
            state["last_progress"] = progress
        polygons = result_polygons()
        if polygons and (not state["mesh_states"] or state["mesh_states"][-1] != polygons):
            state["mesh_states"].append(polygons)
            state["updates_while_running"] += 1
            if SHOTS and "screenshot_at" not in state:
                screenshot_in_progress()
    return 0.05


def send_clicks():
    # Once a pass is shown: Ctrl+Z, then the shading pie (Z) over the 3D view,
    # the pointer 150 px down (the pie's south item, Material Preview) and a click,
    # all on the X display, without waiting (the window must handle them).
    if state["start"] is None or not state["mesh_states"]:
        return 0.05
    win, area = window(), view_3d()
    x, y = area.x + area.width // 2, win.height - (area.y + area.height // 2)
    subprocess.Popen(["xdotool", "mousemove", str(x), str(y), "sleep", "0.3", "key", "ctrl+z", "sleep", "0.3",
                      "key", "z", "sleep", "0.8", "mousemove_relative", "0", "150", "sleep", "0.5", "click", "1"])
    state["clicks"] = {"sent_at": time.time() - state["start"], "shading": [], "polygons": result_polygons()}
    bpy.app.timers.register(watch_shading, first_interval=0.05)
    return None


def watch_shading():
    # The view's shading as the solve goes on; Esc once it reads Material Preview.
    progress, clicks = operators.running_progress(), state["clicks"]
    shading = view_3d().spaces.active.shading.type
    if not clicks["shading"] or clicks["shading"][-1][0] != shading:
        clicks["shading"].append([shading, progress is not None, result_polygons(),
                                  bpy.context.scene.radiosity.quality, (progress or {}).get("pass")])
    if progress is None:
        return None
    if shading == 'MATERIAL':
        press_escape()
        return None
    return 0.05


def in_view_3d(operator, **kwargs):
    # An operator as a menu item in the 3D view runs it.
    win = window()
    with bpy.context.temp_override(window=win, screen=win.screen, area=view_3d()):
        return sorted(operator(**kwargs))


def undo_from_menu():
    if state["start"] is None or not state["mesh_states"]:
        return 0.05
    state["menu_undo"] = {"running_before": operators.running_progress() is not None,
                          "undo": in_view_3d(bpy.ops.ed.undo)}
    return None


def edit_mode():
    # Back to Object Mode once the solver has finished (start() went into Edit
    # Mode), noting whether the result waited (no statistics, no pass shown yet).
    if "edit_mode" not in state:
        return 0.05
    job = operators._running_job
    if job is not None and job.result is None and job.error is None:
        return 0.05  # the solver still runs
    state["edit_mode"].update(finished_running=job is not None, valid_before=bpy.context.scene.radiosity.stats.valid,
                              polygons_before=result_polygons())
    state["edit_mode"]["leave"] = in_view_3d(bpy.ops.object.mode_set, mode='OBJECT')
    return None


def press_escape():
    # A real key press on the X display (XTEST), into the window under the pointer.
    win = window()
    subprocess.run(["xdotool", "mousemove", str(win.width // 2), str(win.height // 2), "key", "Escape"],
                   check=True, timeout=10)


def escape_after(seconds):
    def escape_now():
        if state["start"] is None or time.time() - state["start"] < seconds:
            return 0.02
        press_escape()
        state["escaped_at"] = time.time() - state["start"]
        return None
    return escape_now


def escape():
    # After the first complete pass, however loaded the machine (a fixed delay
    # failed when the machine was busy), and before the solve at quality 1 ends.
    if state["start"] is None or not first_pass_done():
        return 0.05
    press_escape()
    return None


def check():
    if state["start"] is None:
        return 0.2
    stats = bpy.context.scene.radiosity.stats
    if not stats.valid and not state.get("ended") and time.time() - state["start"] < 120:
        return 0.2
    results = [o for o in bpy.context.scene.objects if o.get("radiosity_result")]
    shading = [s.shading.color_type for a in window().screen.areas for s in a.spaces if s.type == 'VIEW_3D']
    print("RESULT " + json.dumps({
        "invoke": state["invoke"], "quality": bpy.context.scene.radiosity.quality,
        "valid": stats.valid, "status": stats.status,
        "elements": stats.elements, "results": len(results), "shading": shading,
        "hidden": all(o.hide_render for o in bpy.context.scene.objects
                      if o.type == 'MESH' and not o.get("radiosity_result")),
        "fractions": state["fractions"], "last_progress": state["last_progress"],
        "timer_hz": state["ticks"] / max(state["running_seconds"], 1e-9),
        "running_seconds": state["running_seconds"], "updates_while_running": state["updates_while_running"],
        "final_polygons": result_polygons(), "escaped_at": state.get("escaped_at"),
        "leaves_after": state["leaves_after"], "idle_after": state.get("idle_after"),
        "screenshot_at": state.get("screenshot_at"), "clicks": state["clicks"],
        "originals_shown": sorted({(not o.hide_render and not o.hide_get()) for o in bpy.context.scene.objects
                                   if o.type == 'MESH' and not o.get("radiosity_result")}),
        "menu_undo": state.get("menu_undo"), "edit_mode": state.get("edit_mode"), "mode": bpy.context.mode,
    }), flush=True)
    bpy.ops.wm.quit_blender()
    return None


def start_when_idle():
    # Idle: the process used under a tenth of a core over the last quarter
    # second (all its threads: the OpenGL rasteriser's too). At most 30 s.
    now, cpu = time.perf_counter(), time.process_time()
    last = state.get("idle_check")
    state["idle_check"] = (now, cpu)
    waited = now - state["launched"]
    if last is None or (cpu - last[1] > 0.1 * (now - last[0]) and waited < 30.0):
        return 0.25
    state["idle_after"] = waited
    if SHOTS:
        show_the_panel()
    start()
    return None


state["launched"] = time.perf_counter()
if SHOTS:
    bpy.app.timers.register(show_render_tab, first_interval=0.1)
bpy.app.timers.register(start_when_idle, first_interval=0.5)
bpy.app.timers.register(watch, first_interval=0.55)
if MODE == "cancel":
    bpy.app.timers.register(escape, first_interval=0.6)
elif MODE == "clicks":
    bpy.app.timers.register(send_clicks, first_interval=0.6)
elif MODE == "menu_undo":
    bpy.app.timers.register(undo_from_menu, first_interval=0.6)
elif MODE == "edit_mode":
    bpy.app.timers.register(edit_mode, first_interval=0.6)
elif MODE.startswith("cancel_after:"):
    bpy.app.timers.register(escape_after(float(MODE.split(":")[1])), first_interval=0.52)
bpy.app.timers.register(check, first_interval=0.7)
