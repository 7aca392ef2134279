"""A solve without its UI: settings -> native options, export -> solve -> bake.

The operator (ui/operators.py) calls these in order. `prepare` exports the scene
and makes the native Scene and the solver's options (main thread); the native
solve runs in `solve` (on the calling thread) or in `work` (on a worker thread:
it touches no bpy, and the native solve releases the GIL); `conclude` (main
thread) turns the job's error into a SolveError or `finish`es: bakes the result
in one transaction (write/scene_transaction.py) and writes the statistics into
scene.radiosity.stats. Failures the user can act on raise SolveError, whose
message is reported as is; a failure leaves the scene as it was.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from ..model import arrays as model_arrays
from ..model import findings
from ..read import export
from ..write import bake, game_ready, result_state, scene_transaction
from . import solve_reuse

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
    progress: dict = field(default_factory=dict)  # the solver's last report
    monitor: object = None  # the native ProgressMonitor of an interactive solve
    reuse: object = None  # the scene's native SolveReuse (solve_reuse.py)
    result: object = None
    error: BaseException = None
    started: float = field(default_factory=time.perf_counter)  # when the Solve began
    undone: bool = False  # an undo replaced the scene while it solved (operators._undone)


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
    """A hint when exact visibility made the linking slow. Sampled visibility
    linked the scenes measured 2 to 12 times faster (native/README.md), and the
    links grow with the square of a finely tessellated object's faces: every
    pair of its faces close together is linked."""
    if visibility != 'exact' or stats.get("seconds_linking", 0.0) < 10.0:
        return ""
    links = " (%s links)" % format(stats["links"], ",") if stats.get("links") else ""
    return ("linking took %.0f s with exact visibility%s: Visibility 'Sampled' links 2 to 12 times faster, "
            "and fewer faces on finely tessellated objects (a lower Subdivision level, fewer segments) "
            "link faster still" % (stats["seconds_linking"], links))


# Why a solve stopped before its first pass, in the words of rough_look_hint.
STOPPED_WHILE_LINKING = {
    "time_budget": "the Time Limit ran out",
    "memory": "the memory limit was reached",
    "cancel": "it was cancelled",
}


def rough_look_hint(visibility, stats):
    """What the result is when the solve stopped while it was linking (before
    its first pass): the ray pass's rough look (native/core/solve/ray_pass.h),
    right in brightness but blotchy, and what to change."""
    why = STOPPED_WHILE_LINKING.get(stats.get("stopped_by"))
    if not why or stats.get("passes", 0) or not stats.get("ray_pass_rays"):
        return ""
    return ("Rough look only: %s while linking (%.0f s), so the result is the quick first look traced by rays: "
            "right in brightness, blotchy in detail. For the solved result raise the Time Limit or lower "
            "Quality%s" % (why, stats.get("seconds_linking", 0.0),
                           ", or use Visibility 'Sampled'" if visibility == 'exact' else ""))


def prepare(context, solver, started=None):
    """Export the scene and make the native Scene (main thread); the Solve
    began at `started` (time.perf_counter; None: now)."""
    started = time.perf_counter() if started is None else started
    scene = context.scene
    # What a render shows, the originals the last solve hid included, is read,
    # whatever the viewport hides; every flag is put back after.
    with result_state.OriginalsShown(scene, context.view_layer), export.rendered_shown(context.view_layer):
        exported = export.export_scene(context)
    arrays = exported.arrays
    note = "; ".join(exported.repaired + ([findings.unmodelled_message(exported.unmodelled)]
                                          if exported.unmodelled else []))
    if exported.face_count == 0:
        raise SolveError("Nothing to solve: the scene has no visible mesh objects or area lights"
                         + (" (%s)" % note if note else ""))
    if not np.any(arrays["emission"] > 0) and not exported.lights and exported.world is None:
        raise SolveError("No light to solve: add a light, an emissive material (Emission shader or "
                         "Principled Emission) or a world colour"
                         + (" (%s)" % note if note else ""))
    try:
        native_scene = model_arrays.native_scene(solver, arrays, exported.lights, exported.world)
    except ValueError as err:
        raise SolveError("Radiosity: %s" % err) from None
    settings = scene.radiosity
    label = settings.bl_rna.properties["oracle"].enum_items[settings.oracle].name
    options = native_options(settings.solver_options(), native_scene.total_area)
    options["time_budget"] = solve_budget(settings.time_budget, started, 2 * native_scene.patch_count)
    return Job(scene_name=scene.name, exported=exported, native_scene=native_scene, options=options,
               oracle_label=label, started=started, reuse=solve_reuse.for_scene(solver, scene))


def solve(solver, job, progress=None):
    """The native solve on the calling thread; `progress` is called with the solver's reports."""
    try:
        job.result = solver.solve(job.native_scene, progress=progress, reuse=job.reuse, **job.options)
    except REFUSALS as err:
        raise SolveError("Radiosity: %s" % err) from None


def work(solver, job, token):
    """The worker thread: only the native solve, which releases the GIL and
    reports into job.monitor (polled by the UI) without ever waiting for it."""
    try:
        # The window's thread keeps its priority: Esc, redraws and the timer that
        # shows the passes stay prompt while the solve takes every idle cycle.
        job.result = solver.solve(job.native_scene, progress=job.monitor, cancel=token, reuse=job.reuse,
                                  yield_to_interface=job.monitor is not None, **job.options)
    except BaseException as err:  # reported on the main thread
        job.error = err


def conclude(context, job, live=None):
    """Raise a finished job's error (putting back what `live` showed), or
    bake its result (main thread)."""
    if job.error is not None:
        if live is not None:
            live.abort(job.error)
        if isinstance(job.error, REFUSALS):
            raise SolveError("Radiosity: %s" % job.error)
        raise job.error
    try:
        return finish(context, job, live)
    except BaseException as err:
        if live is not None:
            live.abort(err)
        raise


def finish(context, job, live=None):
    """Bake the result into the scene and record the statistics in
    scene.radiosity.stats, which it returns (main thread). `live`: the
    LiveResult that showed the passes of an interactive solve, whose
    transaction this completes."""
    result = job.result
    stats = result.stats
    if len(result.face_sizes) == 0:
        if stats.get("cancelled"):
            raise SolveError("Radiosity solve cancelled before the first pass: scene unchanged")
        raise SolveError("Radiosity: the solver returned no surfaces (every face degenerate?)")
    if live is not None:
        skipped_objects, warnings = live.finish(context, job, result)
    else:
        # One transaction: a failure at any step leaves the scene as it was (scene_transaction.py).
        with scene_transaction.SceneTransaction(context.scene, context.view_layer) as transaction:
            skipped_objects, warnings = bake_result(context, job, result,
                                                    lambda _: transaction.retire_results())
    return record(context, job, stats, skipped_objects, warnings)


def bake_result(context, job, result, replace_previous):
    """Write `result` into the scene as the settings' output asks (inside a
    SceneTransaction); `replace_previous(scene)` takes the result shown before
    away. Returns the objects that got no attribute and the warnings."""
    scene = context.scene
    settings = scene.radiosity
    mode = settings.output
    skipped_objects = []
    warnings = []
    convert = material = None
    # Lit Materials keeps the user's materials, which no unlit material can
    # stand in for: game-ready colours apply to the other outputs.
    if settings.display_colours and mode != 'LIGHTING':
        convert, material, note = game_ready.bake_options(scene)
        if note:
            warnings.append(note)
    if mode in {'REFINED', 'BOTH', 'LIGHTING'}:
        bake.write_refined(scene, job.exported, result, settings.show_wireframe,
                           convert=convert, material=material, lighting=mode == 'LIGHTING',
                           replace_previous=replace_previous)
        result_state.hide_originals(scene, context.view_layer, job.exported.hidden_sources)
        result_state.show_results(scene, True)
    else:
        replace_previous(scene)
        result_state.restore_originals(scene, context.view_layer)
    if mode in {'ORIGINAL', 'BOTH'}:
        skipped_objects = bake.write_original(scene, job.exported, result, convert=convert)
    result_state.show_in_views(scene)
    return skipped_objects, warnings


class LiveResult:
    """An interactive solve's result shown as it refines: each pass's solution
    replaces the one before, all inside one SceneTransaction that the final
    result commits, so a failed solve still leaves the scene as it was and a
    cancelled one keeps its last pass (main thread)."""

    def __init__(self, context):
        self.transaction = scene_transaction.SceneTransaction(context.scene, context.view_layer)
        self.transaction.__enter__()
        self.passes_shown = 0
        self.outcome = ([], [])  # what the last bake returned (bake_result)
        self.open = True

    def _replace(self, scene):
        # The user's previous result is retired (kept for a rollback); an
        # earlier pass's meshes are this solve's own and simply go.
        if self.passes_shown == 0:
            self.transaction.retire_results()
        else:
            result_state.remove_results(scene)

    def show(self, context, job, result):
        """Bake one pass's solution (`result`, from the solver's ProgressMonitor)."""
        try:
            self.outcome = bake_result(context, job, result, self._replace)
        except BaseException as err:
            self.abort(err)
            raise
        self.passes_shown = int(result.stats.get("passes", self.passes_shown + 1))

    def finish(self, context, job, result):
        """Bake the final result unless the last pass shown was it, and commit."""
        try:
            if self.passes_shown != int(result.stats.get("passes", -1)) or self.passes_shown == 0:
                self.outcome = bake_result(context, job, result, self._replace)
        except BaseException as err:
            self.abort(err)
            raise
        self.open = False
        self.transaction.__exit__(None, None, None)
        return self.outcome

    def abort(self, error=None):
        """Put the scene back as it was before the solve."""
        if self.open:
            self.open = False
            error = error or RuntimeError("solve abandoned")
            self.transaction.__exit__(type(error), error, None)


def record(context, job, stats, skipped_objects, warnings):
    """The warnings and statistics of a finished solve into scene.radiosity.stats."""
    settings = context.scene.radiosity
    warnings.extend(job.exported.repaired)
    face_object = export.face_object(job.exported)
    native_scene = job.native_scene
    for message in (findings.unmodelled_message(job.exported.unmodelled),
                    rough_look_hint(job.options.get("visibility"), stats),
                    visibility_hint(job.options.get("visibility"), stats),
                    findings.coincident_message(face_object, native_scene.coincident_faces),
                    findings.face_notes_message(face_object, native_scene.skipped_faces, "faces left out:"),
                    findings.face_notes_message(face_object, native_scene.repaired_faces, "faces repaired:")):
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
    s.relit = bool(stats.get("reused", False))
    # Why a solve that could have relit linked anew (nothing said the first time).
    s.relinked_because = findings.relink_reason(stats.get("reuse_refusal", ""))
    s.warning = "; ".join(warnings)
    return s
