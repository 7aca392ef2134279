"""Operators of the Radiosity add-on: UI and modal only.

`radiosity.solve` is the one entry point for users, scripts and tests. Its
execute runs the whole solve synchronously (background mode, scripts, tests);
invoke, from the UI, runs the same solve on a worker thread with a progress
bar, status text and ESC to cancel (the solver then returns its last complete
pass, which is baked). The window stays usable meanwhile: the modal handler
passes every event on but Esc and the keys of what must wait for the solve
(LOCKED_OPERATORS); an undo from a menu stops the solve. Both paths run the
steps of pipeline.py: `prepare` (export, on the main thread), the native solve,
and `conclude` (bake, on the main thread): bpy is never touched from the
worker. Every failure becomes a report and {'CANCELLED'}, never a traceback,
and leaves the scene as it was.

`radiosity.toggle_result` switches between the solution and the originals;
`radiosity.clear` removes the solution and restores the originals
(result_state.py).
"""

import sys
import threading
import time
import traceback

import bpy
from bpy.app.handlers import persistent
from bpy.types import Operator

from ..model.progress_text import status_line
from ..solve import native, pipeline, solve_reuse
from ..write import bake, result_state
from . import live_pacing, view_sync

# The interactive solve in progress (at most one: the operator is modal), so
# that scripts and the UI can follow it.
_running_job = None


def running_progress():
    """The progress dict of the interactive solve running now (the solver's
    last report: pass, passes, phase, elements, leaves, links, seconds,
    fraction), or None when none runs."""
    job = _running_job
    return None if job is None else dict(job.progress)


def refused_while_solving(operator):
    """True (with the reason for the tooltip) while an interactive solve runs: its
    passes and final bake own the result until it ends."""
    if _running_job is None:
        return False
    operator.poll_message_set("A radiosity solve is running (Esc cancels it)")
    return True


# What waits while an interactive solve runs: its keys do nothing (the status bar
# says why). Undo and redo would take the scene back under the passes the solve
# shows, deleting or switching the mode of an object would pull its meshes from
# under the bake, and a repeat would start the same again. The solve's own
# buttons (Solve, Toggle, Remove) are greyed by their polls.
LOCKED_OPERATORS = {
    "ed.undo": "Undo", "ed.redo": "Redo", "ed.undo_history": "Undo History",
    "screen.repeat_last": "Repeat Last", "screen.repeat_history": "Repeat History",
    "object.delete": "Delete", "outliner.delete": "Delete", "object.join": "Join",
    "object.editmode_toggle": "Edit Mode", "object.mode_set": "Mode switching",
    "object.transfer_mode": "Mode switching",
}
LOCKED_MENUS = {"VIEW3D_MT_object_mode_pie": "Mode switching"}
# What undoing through a menu (which no key passes) does to a running solve.
UNDONE = "Undo during the radiosity solve stopped it: the scene is as before the solve"


def _modifier_matches(wanted, pressed, any_modifier):
    # KeyMapItem modifiers: bools before 3.2, then -1 (any), 0 or 1.
    return any_modifier or wanted == -1 or bool(wanted) == pressed


def locked_keys(keyconfig):
    """[(event type, shift, ctrl, alt, oskey, any, what)] of the keymap items of
    `keyconfig` that call a locked operator or menu."""
    keys = []
    for keymap in keyconfig.keymaps if keyconfig is not None else ():
        for item in keymap.keymap_items:
            what = LOCKED_OPERATORS.get(item.idname)
            if what is None and item.idname in {"wm.call_menu", "wm.call_menu_pie"}:
                what = LOCKED_MENUS.get(getattr(item.properties, "name", ""))
            if what is not None and item.active and item.key_modifier == 'NONE':
                keys.append((item.type, item.shift, item.ctrl, item.alt, item.oskey, item.any, what))
    return keys


def locked_by(keys, event):
    """What `event` would start that must wait for the solve, or None."""
    for kind, shift, ctrl, alt, oskey, any_modifier, what in keys:
        if kind == event.type and all(_modifier_matches(w, p, any_modifier) for w, p in (
                (shift, event.shift), (ctrl, event.ctrl), (alt, event.alt), (oskey, event.oskey))):
            return what
    return None


@persistent
def _undone(*_args):
    # An undo or redo while a solve runs (from a menu: its keys are locked)
    # replaced the scene under it: the solve stops and bakes nothing.
    job = _running_job
    if job is not None:
        job.undone = True


UNDO_HANDLERS = (bpy.app.handlers.undo_post, bpy.app.handlers.redo_post)


def register():
    view_sync.attach(_undone, UNDO_HANDLERS)


def unregister():
    view_sync.detach(_undone, UNDO_HANDLERS)


def pass_printer():
    """A progress callback that prints one line per pass."""
    last = [None]

    def progress(p):
        if p.get("pass") != last[0]:
            last[0] = p.get("pass")
            print(status_line(p), flush=True)
    return progress


def redraw_panels(context):
    """Redraws the panels that show the progress (Properties, the 3D view's
    sidebar) with the status bar, not the 3D views themselves: a view's redraw
    costs as much as the solve under software OpenGL (_show_status), and the panel
    froze at one pass's value while the status bar went on to the next."""
    for area in context.screen.areas if context.screen else ():
        if area.type == 'PROPERTIES':
            area.tag_redraw()
        elif area.type == 'VIEW_3D':
            for region in area.regions:
                if region.type == 'UI':
                    region.tag_redraw()


class RADIOSITY_OT_solve(Operator):
    """Compute the diffuse lighting of the scene with hierarchical radiosity and bake it into colour attributes"""

    bl_idname = "radiosity.solve"
    bl_label = "Solve Radiosity"
    # The solve writes meshes and attributes, so it is one undo step.
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if context.scene is None or refused_while_solving(cls):
            return False
        # In Edit Mode the mesh data blocks lag behind the edit meshes, so a
        # solve would silently use stale geometry.
        if context.mode != 'OBJECT':
            cls.poll_message_set("Switch to Object Mode to solve radiosity")
            return False
        return True

    def execute(self, context):
        return self._run(context)

    def invoke(self, context, event):
        started = time.perf_counter()
        if bpy.app.background or context.window is None:
            return self._run(context)
        try:
            solver = native.load()
            job = pipeline.prepare(context, solver, started)
        except (native.NativeUnavailable, pipeline.SolveError) as err:
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        except Exception as err:
            return self._unexpected(err)
        global _running_job
        self._job = _running_job = job
        job.monitor = solver.ProgressMonitor(pass_results=True)
        self._live = None  # the passes shown so far (pipeline.LiveResult)
        self._pacing = live_pacing.LivePacing()
        self._status, self._status_time = "", 0.0  # the status text shown, and when
        self._token = solver.CancelToken()
        self._locked_keys = locked_keys(context.window_manager.keyconfigs.user)
        self._waiting_said = False  # the status says the bake waits for Object Mode
        self._thread = threading.Thread(target=pipeline.work, args=(solver, job, self._token),
                                        name="radiosity-solve", daemon=True)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        context.workspace.status_text_set(status_line({}) + "  (Esc to cancel)")
        self._thread.start()
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            self._token.cancel()
            context.workspace.status_text_set("Radiosity: cancelling, keeping the last complete pass")
            return {'RUNNING_MODAL'}
        if self._job.undone:
            return self._drop_undone(context)
        # Any timer tick will do (other timers tick too, and pass on to their owners).
        if event.type == 'TIMER':
            alive = self._thread.is_alive()
            self._poll(context)
            if alive:
                return {'PASS_THROUGH'}
            if context.mode != 'OBJECT':
                # The bake waits for Object Mode (a mode switched from a menu).
                if not self._waiting_said:
                    self._waiting_said = True
                    context.workspace.status_text_set("Radiosity: solved; the result is baked "
                                                      "once you are back in Object Mode")
                return {'PASS_THROUGH'}
            self._stop_modal(context)
            return self._conclude(context, self._job, self._live)
        what = locked_by(self._locked_keys, event)
        if what is not None:
            if event.value == 'PRESS':
                self.report({'WARNING'}, "%s waits until the radiosity solve ends (Esc cancels it)" % what)
            return {'RUNNING_MODAL'}
        return {'PASS_THROUGH'}  # the rest of the interface works as ever

    def _drop_undone(self, context):
        """An undo replaced the scene: stop the solver and put the scene back as
        it was before the solve. Blender's undo keeps the objects it finds
        unchanged since its last step, and the passes' changes made no step: the
        originals the passes hid would stay hidden, with no result to show."""
        self._token.cancel()
        self._thread.join()
        self._stop_modal(context)
        if self._live is not None:
            try:
                self._live.abort()
            except ReferenceError:
                # The undo read the scene anew (the transaction's scene is gone): the
                # originals come back by their tags.
                result_state.restore_originals(context.scene, context.view_layer)
            self._live = None
        result_state.sync_views(context.scene)
        self.report({'WARNING'}, UNDONE)
        return {'CANCELLED'}

    def cancel(self, context):
        # Blender ends the operator (file closed, window gone): stop the worker
        # and put back what the passes showed.
        self._token.cancel()
        self._thread.join()
        self._stop_modal(context)
        if self._live is not None:
            self._live.abort()

    def _poll(self, context):
        """Show the solver's progress and the newest pass's solution (timer, main thread)."""
        job = self._job
        progress = job.monitor.progress()
        if progress is not None:
            job.progress = progress
        # A newer pass replaces one waiting in the monitor while the pacing says wait;
        # none is shown outside Object Mode (an object edited from a menu).
        may_show = self._pacing.may_show() and context.mode == 'OBJECT'
        result = job.monitor.take_pass_result() if may_show else None
        if result is not None:
            try:
                began = time.perf_counter()
                if self._live is None:
                    self._live = pipeline.LiveResult(context)
                self._live.show(context, job, result)
                self._pacing.shown(began, time.perf_counter())
            except Exception:
                # The scene is back as it was (LiveResult.abort); the solve goes on
                # and its final bake reports what fails.
                traceback.print_exc(file=sys.stderr)
                self._live = None
            # Redraw the panels too: the statistics and the progress bar live there.
            for area in context.screen.areas if context.screen else ():
                if area.type in {'VIEW_3D', 'PROPERTIES'}:
                    area.tag_redraw()
        self._show_status(context, progress, with_pass=result is not None)

    def _show_status(self, context, progress, with_pass):
        """The status text and cursor: at most once a second, or with a pass shown.

        Each change redraws part of the window, which costs as much CPU as the
        solve with software OpenGL (measured under Xvfb: full_office took 18 s
        with an update every tick, 9 s without); with a pass it comes with the
        redraw the pass needs anyway."""
        if progress is None or self._token.cancelled:
            return
        now = time.perf_counter()
        text = status_line(progress)
        if text != self._status and (with_pass or now - self._status_time >= 1.0):
            self._status, self._status_time = text, now
            context.window_manager.progress_update(100.0 * float(progress.get("fraction", 0.0)))
            context.workspace.status_text_set(text + "  (Esc to cancel)")
            redraw_panels(context)

    def _stop_modal(self, context):
        global _running_job
        _running_job = None
        self._pacing.close()
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        context.workspace.status_text_set(None)

    def _run(self, context):
        """The whole solve on the main thread: export, solve with the native module, bake."""
        started = time.perf_counter()
        try:
            solver = native.load()
            job = pipeline.prepare(context, solver, started)
            # Headless users see one line per pass.
            pipeline.solve(solver, job, progress=pass_printer() if bpy.app.background else None)
        except (native.NativeUnavailable, pipeline.SolveError) as err:
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        except Exception as err:
            return self._unexpected(err)
        return self._conclude(context, job)

    def _conclude(self, context, job, live=None):
        """Bake a finished job's result and report how the solve ended, or
        report its error (main thread). `live`: the passes shown so far."""
        try:
            stats = pipeline.conclude(context, job, live)
        except pipeline.SolveError as err:
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        except Exception as err:
            return self._unexpected(err)
        if stats.warning:
            self.report({'WARNING'}, stats.warning)
        self.report({'INFO'}, "Radiosity: %s%s, %s elements in %.2f s"
                    % (stats.status.lower(), " (relit: only the lighting had changed)" if stats.relit else "",
                       "{:,}".format(stats.elements), stats.seconds))
        return {'FINISHED'}

    def _unexpected(self, err):
        # A bug: the traceback goes to the console for whoever fixes it, the
        # user gets a report.
        traceback.print_exc(file=sys.stderr)
        self.report({'ERROR'}, "Radiosity solve failed unexpectedly: %s: %s"
                    % (type(err).__name__, err))
        return {'CANCELLED'}


class RADIOSITY_OT_toggle_result(Operator):
    """Switch between showing the radiosity solution and the original objects"""

    bl_idname = "radiosity.toggle_result"
    bl_label = "Toggle Radiosity Result"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if refused_while_solving(cls):
            return False
        return context.scene is not None and bool(result_state.result_objects(context.scene))

    def execute(self, context):
        result_state.toggle(context.scene, context.view_layer)
        return {'FINISHED'}


class RADIOSITY_OT_clear(Operator):
    """Remove the radiosity solution and show the original objects again"""

    bl_idname = "radiosity.clear"
    bl_label = "Remove Radiosity Result"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if context.scene is None or refused_while_solving(cls):
            return False
        if not result_state.anything_to_remove(context.scene) and not context.scene.radiosity.stats.valid:
            cls.poll_message_set("No radiosity result to remove")
            return False
        return True

    def execute(self, context):
        scene = context.scene
        result_state.clear(scene, context.view_layer)
        bake.remove_original_attributes(scene)
        solve_reuse.forget(scene)
        scene.radiosity.stats.clear()
        return {'FINISHED'}
