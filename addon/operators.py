"""Operators of the Radiosity add-on.

`radiosity.solve` is the one entry point for users, scripts and tests. Its
execute runs the whole solve synchronously (background mode, scripts, tests);
invoke, from the UI, runs the same solve on a worker thread with a progress
bar, status text and ESC to cancel (the solver then returns its last complete
pass, which is baked). Both paths share `_prepare` (export, on the main thread),
the native solve, and `_finish` (bake, on the main thread): bpy is never touched
from the worker. Every failure becomes a report and {'CANCELLED'}, never a
traceback, and leaves the scene as it was.

`radiosity.toggle_result` switches between the solution and the originals;
`radiosity.clear` removes the solution and restores the originals.
"""

import sys
import threading
import time
import traceback
from dataclasses import dataclass, field

import bpy
import numpy as np
from bpy.types import Operator

from . import bake, export, game_export, native, result_state, scene_transaction

STATUS = {
    "quality": "Converged",
    "max_elements": "Element budget reached",
    "memory": "Memory limit reached (refinement stopped there)",
    "time_budget": "Time budget reached",
    "cancel": "Cancelled (last complete pass kept)",
}


class SolveError(Exception):
    """A failure the user can act on; its message is reported as is."""


# What the native module raises for input it refuses (ValueError) or a scene
# too large for memory (MemoryError): the user can act on both.
REFUSALS = (ValueError, MemoryError)


@dataclass
class Job:
    """What a solve carries from the main thread to the worker and back."""
    scene_name: str
    exported: export.ExportedScene
    native_scene: object
    options: dict
    oracle_label: str
    progress: dict = field(default_factory=dict)
    result: object = None
    error: BaseException = None
    started: float = field(default_factory=time.perf_counter)  # when the Solve began


def native_options(options, total_area):
    """scene.radiosity.solver_options() in the form rad.solve takes (0 = no limit or
    automatic); the smallest element's edge becomes a fraction of the scene's area."""
    extra = {}
    size = float(options.get("min_element_size", 0.0))
    if size > 0.0 and total_area > 0.0:
        extra["min_element_area"] = min(size * size / total_area, 0.5)
    return extra | {
        "oracle": options["oracle"],
        "quality": float(options["quality"]),
        "max_elements": int(options["max_elements"]) or None,
        "time_budget": float(options["time_budget"]) or None,
        "visibility": options["visibility"],
        "rays": int(options["rays"]),
        "bounces": int(options["bounces"]) or None,
    }


# Writing a result into the scene (meshes, attributes, UV maps) takes about
# this long per element on the 2-core reference machine (7.5 s for the 400,000
# elements of a 200,000-face plane, bench/addon_budget.py).
WRITE_SECONDS_PER_ELEMENT = 2e-5
# What the solver gets when the export has used up the budget: its first pass.
MIN_SOLVE_BUDGET = 0.05


def solve_budget(budget, started, elements):
    """The share of the user's time budget (seconds; 0: no limit) left to the
    solver: the budget is for the whole Solve, so what the export took since
    `started` is spent and writing the `elements` the solve starts with is
    kept back."""
    if not budget:
        return None
    left = budget - (time.perf_counter() - started) - WRITE_SECONDS_PER_ELEMENT * elements
    return max(MIN_SOLVE_BUDGET, left)


def visibility_hint(visibility, stats):
    """A hint when exact visibility made the linking of a large scene slow:
    sampled visibility links a 10,000-face room in about half a minute, where
    exact visibility takes many minutes (native/README.md)."""
    if visibility != 'exact' or stats.get("seconds_linking", 0.0) < 10.0:
        return ""
    return ("linking took %.0f s with exact visibility: for scenes this large, Visibility 'Sampled' "
            "is many times faster" % stats["seconds_linking"])


# The interactive solve in progress (at most one: the operator is modal), so
# that scripts and the UI can follow it.
_running_job = None


def running_progress():
    """The progress dict of the interactive solve running now (the solver's
    last report: pass, passes, phase, elements, links, seconds, fraction), or
    None when none runs."""
    job = _running_job
    return None if job is None else dict(job.progress)


def progress_text(progress):
    """One line describing a progress dict of the solver."""
    if not progress:
        return "Radiosity: starting"
    return "Radiosity: pass {} of {}, {}, {:,} elements, {:,} links, {:.1f} s".format(
        progress.get("pass", 0), progress.get("passes", 0), progress.get("phase", ""),
        progress.get("elements", 0), progress.get("links", 0), progress.get("seconds", 0.0))


class RADIOSITY_OT_solve(Operator):
    """Compute the diffuse lighting of the scene with hierarchical radiosity and bake it into colour attributes"""

    bl_idname = "radiosity.solve"
    bl_label = "Solve Radiosity"
    # The solve writes meshes and attributes, so it is one undo step.
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if context.scene is None:
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
            job = self._prepare(context, solver, started)
        except (native.NativeUnavailable, SolveError) as err:
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        except Exception as err:
            return self._unexpected(err)
        global _running_job
        self._job = _running_job = job
        self._token = solver.CancelToken()
        self._thread = threading.Thread(target=self._work, args=(solver, job, self._token),
                                        name="radiosity-solve", daemon=True)
        wm = context.window_manager
        self._timer = wm.event_timer_add(0.1, window=context.window)
        wm.progress_begin(0, 100)
        wm.modal_handler_add(self)
        context.workspace.status_text_set(progress_text({}) + "  (Esc to cancel)")
        self._thread.start()
        return {'RUNNING_MODAL'}

    def modal(self, context, event):
        if event.type == 'ESC' and event.value == 'PRESS':
            self._token.cancel()
            context.workspace.status_text_set("Radiosity: cancelling, keeping the last complete pass")
            return {'RUNNING_MODAL'}
        # Any timer tick will do (other timers tick too; checking is cheap).
        if event.type == 'TIMER':
            if self._thread.is_alive():
                progress = dict(self._job.progress)
                context.window_manager.progress_update(100.0 * float(progress.get("fraction", 0.0)))
                if not self._token.cancelled:
                    context.workspace.status_text_set(progress_text(progress) + "  (Esc to cancel)")
                return {'RUNNING_MODAL'}
            self._stop_modal(context)
            return self._conclude(context, self._job)
        if event.type in {'MIDDLEMOUSE', 'WHEELUPMOUSE', 'WHEELDOWNMOUSE', 'TRACKPADPAN',
                          'TRACKPADZOOM', 'MOUSEMOVE', 'INBETWEEN_MOUSEMOVE'}:
            return {'PASS_THROUGH'}  # let the user look around while it solves
        return {'RUNNING_MODAL'}

    def cancel(self, context):
        # Blender ends the operator (file closed, window gone): stop the worker.
        self._token.cancel()
        self._thread.join()
        self._stop_modal(context)

    def _stop_modal(self, context):
        global _running_job
        _running_job = None
        wm = context.window_manager
        if self._timer is not None:
            wm.event_timer_remove(self._timer)
            self._timer = None
        wm.progress_end()
        context.workspace.status_text_set(None)

    @staticmethod
    def _work(solver, job, token):
        """The worker thread: only the native solve, which releases the GIL."""
        try:
            job.result = solver.solve(job.native_scene, progress=job.progress.update,
                                      cancel=token, **job.options)
        except BaseException as err:  # reported on the main thread
            job.error = err

    def _run(self, context):
        started = time.perf_counter()
        try:
            solver = native.load()
            return self._solve(context, solver, started)
        except (native.NativeUnavailable, SolveError) as err:
            self.report({'ERROR'}, str(err))
        except Exception as err:
            return self._unexpected(err)
        return {'CANCELLED'}

    def _unexpected(self, err):
        # A bug: the traceback goes to the console for whoever fixes it, the
        # user gets a report.
        traceback.print_exc(file=sys.stderr)
        self.report({'ERROR'}, "Radiosity solve failed unexpectedly: %s: %s"
                    % (type(err).__name__, err))
        return {'CANCELLED'}

    def _solve(self, context, solver, started):
        """Export the scene, solve with `solver` (the native module), bake the result."""
        job = self._prepare(context, solver, started)
        progress = None
        if bpy.app.background:
            last = [None]

            def progress(p):
                # Headless users see one line per pass.
                if p.get("pass") != last[0]:
                    last[0] = p.get("pass")
                    print(progress_text(p), flush=True)
        try:
            job.result = solver.solve(job.native_scene, progress=progress, **job.options)
        except REFUSALS as err:
            raise SolveError("Radiosity: %s" % err) from None
        return self._conclude(context, job)

    def _prepare(self, context, solver, started=None):
        """Export the scene and make the native Scene (main thread); the Solve
        began at `started` (time.perf_counter; None: now)."""
        started = time.perf_counter() if started is None else started
        scene = context.scene
        # What a render shows, the originals the last solve hid included, is read,
        # whatever the viewport hides; every flag is put back after.
        with result_state.OriginalsShown(scene, context.view_layer), export.rendered_shown(context.view_layer):
            exported = export.export_scene(context)
        arrays = exported.arrays
        note = "; ".join(exported.repaired + ([export.unmodelled_message(exported.unmodelled)]
                                              if exported.unmodelled else []))
        if exported.face_count == 0:
            raise SolveError("Nothing to solve: the scene has no visible mesh objects or area lights"
                             + (" (%s)" % note if note else ""))
        if not np.any(arrays["emission"] > 0) and not exported.lights and exported.world is None:
            raise SolveError("No light to solve: add a light, an emissive material (Emission shader or "
                             "Principled Emission) or a world colour"
                             + (" (%s)" % note if note else ""))
        try:
            native_scene = solver.Scene(arrays["positions"], arrays["face_vertices"], arrays["face_sizes"],
                                        arrays["reflectance"], arrays["emission"], arrays["two_sided"],
                                        occludes=arrays["occludes"], lights=exported.lights,
                                        world=exported.world)
        except ValueError as err:
            raise SolveError("Radiosity: %s" % err) from None
        settings = scene.radiosity
        label = settings.bl_rna.properties["oracle"].enum_items[settings.oracle].name
        options = native_options(settings.solver_options(), native_scene.total_area)
        options["time_budget"] = solve_budget(settings.time_budget, started, 2 * native_scene.patch_count)
        return Job(scene_name=scene.name, exported=exported, native_scene=native_scene, options=options,
                   oracle_label=label, started=started)

    def _conclude(self, context, job):
        """Report a finished job's error, or bake its result (main thread)."""
        try:
            if job.error is not None:
                if isinstance(job.error, REFUSALS):
                    raise SolveError("Radiosity: %s" % job.error)
                raise job.error
            return self._finish(context, job)
        except SolveError as err:
            self.report({'ERROR'}, str(err))
        except Exception as err:
            return self._unexpected(err)
        return {'CANCELLED'}

    def _finish(self, context, job):
        """Bake the result into the scene and record the statistics."""
        result = job.result
        stats = result.stats
        if len(result.face_sizes) == 0:
            if stats.get("cancelled"):
                raise SolveError("Radiosity solve cancelled before the first pass: scene unchanged")
            raise SolveError("Radiosity: the solver returned no surfaces (every face degenerate?)")
        scene = context.scene
        settings = scene.radiosity
        mode = settings.output
        skipped_objects = []
        warnings = []
        convert = material = None
        # Lighting Only keeps the user's materials, which no unlit material can
        # stand in for: game-ready colours apply to the other outputs.
        if settings.display_colours and mode != 'LIGHTING':
            convert, material, note = game_export.bake_options(scene)
            if note:
                warnings.append(note)
        # One transaction: a failure at any step leaves the scene as it was (scene_transaction.py).
        with scene_transaction.SceneTransaction(scene, context.view_layer) as transaction:
            if mode in {'REFINED', 'BOTH', 'LIGHTING'}:
                bake.write_refined(scene, job.exported, result, settings.show_wireframe,
                                   convert=convert, material=material, lighting=mode == 'LIGHTING',
                                   replace_previous=lambda _: transaction.retire_results())
                result_state.hide_originals(scene, context.view_layer, job.exported.hidden_sources)
                result_state.show_results(scene, True)
            else:
                transaction.retire_results()
                result_state.restore_originals(scene, context.view_layer)
            if mode in {'ORIGINAL', 'BOTH'}:
                skipped_objects = bake.write_original(scene, job.exported, result, convert=convert)
            bake.set_viewport_attribute_colour()

        warnings.extend(job.exported.repaired)
        note = export.unmodelled_message(job.exported.unmodelled)
        if note:
            warnings.append(note)
        hint = visibility_hint(job.options.get("visibility"), stats)
        if hint:
            warnings.append(hint)
        coincident = export.coincident_message(job.exported, job.native_scene.coincident_faces)
        if coincident:
            warnings.append(coincident)
        for notes, what in ((job.native_scene.skipped_faces, "faces left out:"),
                            (job.native_scene.repaired_faces, "faces repaired:")):
            message = export.face_notes_message(job.exported, notes, what)
            if message:
                warnings.append(message)
        for reason in sorted({why for _, why in skipped_objects}):
            warnings.append("no attribute on %s (%s)" % (
                ", ".join(sorted({name for name, why in skipped_objects if why == reason})), reason))
        s = settings.stats
        s.valid = True
        s.status = STATUS.get(stats.get("stopped_by", ""), str(stats.get("stopped_by", "")))
        s.oracle = job.oracle_label
        s.elements = int(stats.get("leaves", 0))
        s.links = int(stats.get("links", 0))
        s.iterations = int(stats.get("iterations", 0))
        s.seconds = float(stats.get("seconds", 0.0))
        s.warning = "; ".join(warnings)
        if warnings:
            self.report({'WARNING'}, s.warning)
        self.report({'INFO'}, "Radiosity: %s, %s elements in %.2f s"
                    % (s.status.lower(), "{:,}".format(s.elements), s.seconds))
        return {'FINISHED'}


class RADIOSITY_OT_toggle_result(Operator):
    """Switch between showing the radiosity solution and the original objects"""

    bl_idname = "radiosity.toggle_result"
    bl_label = "Toggle Radiosity Result"
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
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
        return context.scene is not None

    def execute(self, context):
        scene = context.scene
        result_state.clear(scene, context.view_layer)
        bake.remove_original_attributes(scene)
        scene.radiosity.stats.clear()
        return {'FINISHED'}
