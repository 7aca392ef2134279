"""Blender side of test_panel_screenshot.py: the Radiosity panel in a real window.

    xvfb-run -a -s "-screen 0 1280x800x24" blender --factory-startup --enable-event-simulate \
        FILE.blend --python panel_screenshot.py -- ADDON_DIR OUT_DIR

Solves the file's scene, shows Properties > Render at the factory layout's width
(the Outliner above it made small, so the editor gets the window's height),
scrolled to the add-on's panels at the end, and saves:
  OUT_DIR/panel.png           the Properties editor after a solve, the top of the
                              Radiosity panel (Solve) at the top
  OUT_DIR/panel_end.png       the same scrolled to the end (the statistics)
  OUT_DIR/panel_progress.png  while a (simulated) solve runs, with a result object
                              selected (the "edits are replaced" warning)
  OUT_DIR/window.png          the whole window of the first
  OUT_DIR/search.png          the window with F3 menu search for "radiosity"
  OUT_DIR/sidebar.png         the 3D view with its sidebar (N) on the Radiosity tab
Prints one line "RESULT <json>" (the Properties region's size, whether the
result objects were selectable, whether UILayout.progress drew the bar, the
files) before quitting.
"""

import json
import os
import sys
import traceback

import addon_utils
import bpy

ADDON, OUT = sys.argv[sys.argv.index("--") + 1:][:2]
sys.path.insert(0, ADDON)


def fail(err):
    raise err


addon_utils.enable("radiosity", default_set=False, handle_error=fail)
from radiosity.ui import operators, panels  # noqa: E402  (the add-on, enabled above)
from radiosity.write import result_state

# The progress dict an interactive solve reports (operators.running_progress).
FAKE_PROGRESS = {"fraction": 0.43, "pass": 2, "passes": 7, "leaves": 12316, "elements": 24631,
                 "links": 402113, "seconds": 4.2, "phase": "pass"}
state = {"step": 0, "files": [], "result": {}}
saved_progress = operators.running_progress


def window():
    return bpy.context.window_manager.windows[0]


def properties_area():
    return next(a for a in window().screen.areas if a.type == 'PROPERTIES')


def region(area, kind='WINDOW'):
    return next(r for r in area.regions if r.type == kind)


def show_render_tab():
    """Render tab, and the edge between the Outliner above and Properties dragged up
    (simulated mouse events), so the editor keeps its width and gets the window's height."""
    win, area = window(), properties_area()
    area.spaces.active.context = 'RENDER'
    outliner = next((a for a in win.screen.areas if a.type == 'OUTLINER'), None)
    if outliner is None or outliner.x != area.x:
        return
    x, y = area.x + area.width // 2, (outliner.y + area.y + area.height) // 2
    top = outliner.y + outliner.height - 40
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
    for step_y in range(y, top, 20):
        win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=step_y)
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=top)
    win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=top)
    # Then rest the pointer over the 3D view, where it changes nothing drawn here.
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=area.x // 2, y=win.height // 2)


def scroll_to_end(back=0):
    """Scroll the Properties to the end (the add-on's panels), then `back` steps of
    40 pixels (a wheel step: the operator's own) up."""
    win, area = window(), properties_area()
    with bpy.context.temp_override(window=win, screen=win.screen, area=area, region=region(area)):
        for _ in range(100):
            bpy.ops.view2d.scroll_down()
        for _ in range(back):
            bpy.ops.view2d.scroll_up()


def search(text, start=False):
    """F3 menu search over the 3D view, typing `text` (the second call)."""
    win = window()
    view = next(a for a in win.screen.areas if a.type == 'VIEW_3D')
    x, y = view.x + view.width // 2, view.y + view.height // 2
    if start:
        win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
        win.event_simulate(type='F3', value='PRESS', x=x, y=y)
        win.event_simulate(type='F3', value='RELEASE', x=x, y=y)
        return
    for char in text:
        win.event_simulate(type=char.upper(), value='PRESS', unicode=char, x=x, y=y)
        win.event_simulate(type=char.upper(), value='RELEASE', x=x, y=y)


def solve():
    scene = bpy.context.scene
    scene.radiosity.quality = 0.3
    with bpy.context.temp_override(window=window()):
        bpy.ops.radiosity.solve('EXEC_DEFAULT')


def view_area():
    return next(a for a in window().screen.areas if a.type == 'VIEW_3D')


def close_search():
    win, view = window(), view_area()
    x, y = view.x + view.width // 2, view.y + view.height // 2
    win.event_simulate(type='ESC', value='PRESS', x=x, y=y)
    win.event_simulate(type='ESC', value='RELEASE', x=x, y=y)


def show_sidebar(attempt=0):
    """The 3D view's sidebar (N) open, and a click on its tab strip at the right
    edge, lower each attempt (Region.active_panel_category is not in 3.4), until
    the Radiosity tab is the one drawn (count_sidebar_draws)."""
    view = view_area()
    view.spaces.active.show_region_ui = True
    sidebar = region(view, 'UI')
    x, y = sidebar.x + sidebar.width - 8, sidebar.y + sidebar.height - 40 - 30 * attempt
    win = window()
    win.event_simulate(type='MOUSEMOVE', value='NOTHING', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='PRESS', x=x, y=y)
    win.event_simulate(type='LEFTMOUSE', value='RELEASE', x=x, y=y)


def count_sidebar_draws():
    """Counts the draws of the sidebar's Radiosity panel (drawn only on its tab)."""
    drawn = panels.VIEW3D_PT_radiosity.draw

    def draw(panel, context):
        state["sidebar_draws"] = state.get("sidebar_draws", 0) + 1
        drawn(panel, context)
    bpy.types.VIEW3D_PT_radiosity.draw = draw


def screenshot(name, whole=False, area=None):
    path = os.path.join(OUT, name)
    win, area = window(), area or properties_area()
    if whole:
        with bpy.context.temp_override(window=win, screen=win.screen, area=area):
            bpy.ops.screen.screenshot(filepath=path)
    else:
        with bpy.context.temp_override(window=win, screen=win.screen, area=area):
            bpy.ops.screen.screenshot_area(filepath=path)
    state["files"].append(path)


def redraw():
    for area in window().screen.areas:
        area.tag_redraw()


def step():
    """One step per timer tick, so that the window draws in between."""
    try:
        n = state["step"]
        state["step"] += 1
        if n == 0:
            os.makedirs(OUT, exist_ok=True)
            show_render_tab()
            solve()
        elif n in (1, 2):
            # Twice: the panels' heights are known after a draw. Six steps back show
            # the top of the Radiosity panel: the Solve button.
            scroll_to_end(6)
        elif n == 3:
            area = properties_area()
            state["result"]["region"] = [region(area).width, region(area).height]
            screenshot("panel.png")
            screenshot("window.png", whole=True)
            scroll_to_end()
        elif n == 4:
            screenshot("panel_end.png")
            # A solve in progress, and a result object selected through the Outliner.
            operators.running_progress = lambda: dict(FAKE_PROGRESS)
            results = result_state.result_objects(bpy.context.scene)
            state["result"]["selectable"] = [o.name for o in results if not o.hide_select]
            state["result"]["results"] = len(results)
            if results:
                results[0].hide_select = False
                results[0].select_set(True)
                bpy.context.view_layer.objects.active = results[0]
        elif n in (5, 6):
            scroll_to_end(12)  # the bar's rows, the lock and the warning make the panel taller
        elif n == 7:
            screenshot("panel_progress.png")
            state["result"]["progress_api"] = hasattr(bpy.types.UILayout, "progress")
            operators.running_progress = saved_progress
            search("radiosity", start=True)
        elif n == 8:
            search("radiosity")
        elif n == 9:
            screenshot("search.png", whole=True)
            close_search()
        elif n == 10:
            count_sidebar_draws()
            view_area().spaces.active.show_region_ui = True
        elif n < 22 and not state.get("sidebar_draws"):
            show_sidebar(n - 11)
        elif "sidebar_draws" in state and "sidebar" not in state:
            state["sidebar"] = True
            screenshot("sidebar.png", area=view_area())
            state["result"]["sidebar_drawn"] = state["sidebar_draws"]
        else:
            finish()
            return None
        redraw()
        return 0.5
    except Exception:
        traceback.print_exc()
        finish()
        return None


def finish():
    state["result"]["files"] = [f for f in state["files"] if os.path.isfile(f)]
    print("RESULT " + json.dumps(state["result"]), flush=True)
    bpy.ops.wm.quit_blender()


bpy.app.timers.register(step, first_interval=1.0)
