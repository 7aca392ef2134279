"""A solve that fails or is cancelled at any step (the export, the native solve,
writing its result) leaves the scene exactly as it was, the previous result
included (addon/write/scene_transaction.py).

Each step the operator takes after the native solve (replacing the result
objects, hiding the originals, showing the results, writing the attribute on
the originals, switching the 3D views to attribute colours) is made to fail
after doing its work, the worst case; steps that loop (writing meshes, their
attributes and lighting materials, writing the originals' attributes, hiding
the originals) also fail half-way; the export fails with viewport-hidden
objects shown for it, the native solve fails or refuses, and a solve is
cancelled before its first pass. The scene is then compared with the scene
before the solve, down to the attribute values, the result meshes and every
visibility flag.
"""

import threading
import unittest

import bpy
import numpy as np

from radiosity.read import export
from radiosity.solve import native, pipeline
from radiosity.ui import operators
from radiosity.write import bake, bake_materials, result_state
from test_addon import scene_snapshot
from test_solve import open_scene

# The steps each output mode takes after the native solve (pipeline.py, finish),
# as (module, function).
STEPS = {
    'REFINED': ((bake, "write_refined"), (result_state, "hide_originals"), (result_state, "show_results"),
                (result_state, "show_in_views")),
    'LIGHTING': ((bake, "write_refined"), (result_state, "hide_originals"), (result_state, "show_results"),
                 (result_state, "show_in_views")),
    'BOTH': ((bake, "write_refined"), (result_state, "hide_originals"), (result_state, "show_results"),
             (bake, "write_original"), (result_state, "show_in_views")),
    'ORIGINAL': ((result_state, "restore_originals"), (bake, "write_original"), (result_state, "show_in_views")),
}


class InjectedFailure(RuntimeError):
    pass


def failing_after(function):
    def step(*args, **kwargs):
        function(*args, **kwargs)
        raise InjectedFailure("injected after %s" % function.__name__)
    return step


def failing_at_call(function, call):
    """`function`, failing instead of its `call`-th call (1-based): half-way through a loop."""
    count = [0]

    def step(*args, **kwargs):
        count[0] += 1
        if count[0] == call:
            raise InjectedFailure("injected at call %d of %s" % (call, function.__name__))
        return function(*args, **kwargs)
    return step


class Patched:
    """with Patched(module, name, wrap): module.name is wrap(original) inside."""

    def __init__(self, module, name, wrap):
        self.module, self.name, self.wrap = module, name, wrap

    def __enter__(self):
        self.original = getattr(self.module, self.name)
        setattr(self.module, self.name, self.wrap(self.original))

    def __exit__(self, *exc):
        setattr(self.module, self.name, self.original)
        return False


def full_state(scene):
    """scene_snapshot plus what it leaves out: attribute values, result meshes, shading."""
    state = scene_snapshot(scene)
    del state["settings"]  # the test changes the settings between solves
    values = {}
    for mesh in bpy.data.meshes:
        for name in (bake.ATTRIBUTE, bake_materials.LIGHT_ATTRIBUTE):
            attr = mesh.color_attributes.get(name)
            if attr is not None:
                v = np.empty(4 * len(attr.data), dtype=np.float32)
                attr.data.foreach_get("color", v)
                values[(mesh.name, name)] = (attr.domain, v.round(6).tolist())
    state["attribute values"] = values
    state["result meshes"] = {o.name: (o.data.name, len(o.data.vertices), len(o.data.polygons),
                                       [m.name for m in o.data.materials])
                              for o in result_state.result_objects(scene)}
    state["tags"] = {o.name: dict((k, str(o[k])) for k in o.keys() if k.startswith("radiosity"))
                     for o in scene.objects}
    state["shading"] = [(s.shading.color_type, s.shading.light, s.shading.show_backface_culling)
                        for scr in bpy.data.screens
                        for a in scr.areas for s in a.spaces if s.type == 'VIEW_3D']
    state["saved shading"] = scene.get(result_state.VIEWS_TAG)
    layer = bpy.context.view_layer
    state["object flags"] = {o.name: (o.hide_render, o.hide_viewport, o.hide_get(view_layer=layer),
                                      o.hide_select) for o in scene.objects}
    state["collection flags"] = {c.name: (c.hide_render, c.hide_viewport) for c in bpy.data.collections}
    state["layer collection flags"] = {lc.name: (lc.exclude, lc.hide_viewport)
                                       for lc in layer.layer_collection.children}
    state["data"] = {m.name: (len(m.vertices), len(m.polygons), m.users) for m in bpy.data.meshes}
    return state


def viewport_hidden_objects(scene):
    """Hide objects in the viewport in every way that leaves them rendered (the
    export shows them for the time it reads the scene)."""
    layer = bpy.context.view_layer
    scene.objects["Cube"].hide_set(True, view_layer=layer)
    scene.objects["Wall.Left"].hide_viewport = True
    coll = bpy.data.collections.new("Hidden in viewport")
    scene.collection.children.link(coll)
    coll.objects.link(scene.objects["Wall.Right"])
    scene.collection.objects.unlink(scene.objects["Wall.Right"])
    coll.hide_viewport = True
    layer.layer_collection.children[coll.name].hide_viewport = True


class FailingStepsChangeNothing(unittest.TestCase):
    def check(self, previous_output, output):
        for module, step in STEPS[output]:
            with self.subTest(previous=previous_output, output=output, step=step):
                scene = open_scene("cube")
                if previous_output:
                    scene.radiosity.output = previous_output
                    self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                before = full_state(scene)
                scene.radiosity.output = output
                scene.radiosity.oracle = 'STANDARD'
                original = getattr(module, step)
                setattr(module, step, failing_after(original))
                try:
                    # The operator reports the error, which bpy.ops raises.
                    with self.assertRaisesRegex(RuntimeError, "injected after " + step):
                        bpy.ops.radiosity.solve()
                finally:
                    setattr(module, step, original)
                self.assertEqual(full_state(scene), before)

    def test_first_solve(self):
        self.check(None, 'BOTH')

    def test_re_solve_keeps_the_previous_result(self):
        self.check('BOTH', 'BOTH')

    def test_re_solve_in_another_output_mode(self):
        self.check('REFINED', 'ORIGINAL')
        self.check('ORIGINAL', 'LIGHTING')

    def test_a_failing_export_changes_nothing(self):
        from radiosity.read import export
        scene = open_scene("cube")
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        before = full_state(scene)
        original = export.export_scene
        export.export_scene = failing_after(original)
        try:
            with self.assertRaisesRegex(RuntimeError, "injected after export_scene"):
                bpy.ops.radiosity.solve()
        finally:
            export.export_scene = original
        self.assertEqual(full_state(scene), before)

    def test_half_way_failures_change_nothing(self):
        """A failure inside a step's loop: some meshes, attributes or lighting copies
        written, some originals hidden, the rest not."""
        cases = [
            ('BOTH', 'BOTH', bake, "build_mesh"),                    # writing meshes
            ('REFINED', 'LIGHTING', bake_materials, "lighting_copy"),  # their materials
            ('BOTH', 'REFINED', bake_materials, "add_light_attribute"),  # their attributes
            ('REFINED', 'BOTH', bake, "set_colour_attribute"),       # attributes of meshes
            ('BOTH', 'ORIGINAL', bake, "set_colour_attribute"),      # attributes of the originals
            ('ORIGINAL', 'REFINED', result_state.json, "dumps"),     # hiding the originals
        ]
        for previous, output, module, name in cases:
            with self.subTest(previous=previous, output=output, step=name):
                scene = open_scene("cube")
                scene.radiosity.output = previous
                self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                before = full_state(scene)
                scene.radiosity.output = output
                scene.radiosity.oracle = 'STANDARD'
                with Patched(module, name, lambda f: failing_at_call(f, 2)):
                    with self.assertRaisesRegex(RuntimeError, "injected at call 2 of " + name):
                        bpy.ops.radiosity.solve()
                self.assertEqual(full_state(scene), before)

    def test_a_failing_export_restores_what_it_showed(self):
        for failing in (failing_after, lambda f: failing_at_call(f, 1)):
            scene = open_scene("cube")
            viewport_hidden_objects(scene)
            self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
            before = full_state(scene)
            with Patched(export, "export_scene", failing):
                with self.assertRaisesRegex(RuntimeError, "injected"):
                    bpy.ops.radiosity.solve()
            self.assertEqual(full_state(scene), before)

    def test_a_failing_or_refused_native_solve_changes_nothing(self):
        class Failing:
            """The native module, but its solve (or Scene) raises `error`."""
            def __init__(self, module, where, error):
                self.module, self.where, self.error = module, where, error

            def __getattr__(self, name):
                if name == self.where:
                    def fail(*args, **kwargs):
                        raise self.error
                    return fail
                return getattr(self.module, name)

        for previous in (None, 'BOTH'):
            for where, error, message in (("solve", RuntimeError("injected solve failure"), "injected solve"),
                                          ("solve", MemoryError("injected: too large"), "injected: too large"),
                                          ("Scene", ValueError("injected: refused"), "injected: refused")):
                with self.subTest(previous=previous, where=where, error=type(error).__name__):
                    scene = open_scene("cube")
                    if previous:
                        scene.radiosity.output = previous
                        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                    before = full_state(scene)
                    with Patched(native, "load", lambda f: lambda: Failing(f(), where, error)):
                        with self.assertRaisesRegex(RuntimeError, message):
                            bpy.ops.radiosity.solve()
                    self.assertEqual(full_state(scene), before)

    def test_cancel_before_the_first_pass_changes_nothing(self):
        """The interactive path (worker thread, cancel token, conclude) cancelled
        before the solver completes a pass, with viewport-hidden objects."""
        class Reports:
            def __init__(self):
                self.reports = []

            def report(self, kind, message):
                self.reports.append((kind, message))

        for previous in (None, 'BOTH', 'LIGHTING'):
            with self.subTest(previous=previous):
                scene = open_scene("cube")
                viewport_hidden_objects(scene)
                if previous:
                    scene.radiosity.output = previous
                    self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                before = full_state(scene)
                solver = native.load()
                op = Reports()
                job = pipeline.prepare(bpy.context, solver)
                token = solver.CancelToken()
                token.cancel()
                worker = threading.Thread(target=pipeline.work, args=(solver, job, token))
                worker.start()
                worker.join(120)
                self.assertFalse(worker.is_alive())
                self.assertEqual(operators.RADIOSITY_OT_solve._conclude(op, bpy.context, job), {'CANCELLED'})
                self.assertIn("cancelled before the first pass", op.reports[-1][1])
                self.assertEqual(full_state(scene), before)

    def test_a_failing_interactive_solve_takes_back_the_passes_it_showed(self):
        """The passes an interactive solve showed live (pipeline.LiveResult) go
        when it fails, and the previous result comes back; when it succeeds its
        last pass stands."""
        for previous in (None, 'REFINED', 'BOTH'):
            with self.subTest(previous=previous):
                scene = open_scene("cube")
                scene.radiosity.quality = 0.3
                if previous:
                    scene.radiosity.output = previous
                    self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                for space in (s for scr in bpy.data.screens for a in scr.areas for s in a.spaces
                              if s.type == 'VIEW_3D'):
                    space.shading.light = 'MATCAP'
                before = full_state(scene)
                solver = native.load()
                job = pipeline.prepare(bpy.context, solver)
                job.monitor = solver.ProgressMonitor(pass_results=True)
                pipeline.work(solver, job, solver.CancelToken())  # on this thread
                live = pipeline.LiveResult(bpy.context)
                live.show(bpy.context, job, job.monitor.take_pass_result())
                self.assertNotEqual(full_state(scene), before, "the pass is shown")
                job.error = RuntimeError("injected after a pass was shown")
                with self.assertRaisesRegex(RuntimeError, "injected"):
                    pipeline.conclude(bpy.context, job, live)
                self.assertEqual(full_state(scene), before)

    def test_an_interactive_solve_keeps_its_last_pass(self):
        scene = open_scene("cube")
        scene.radiosity.quality = 0.3
        solver = native.load()
        job = pipeline.prepare(bpy.context, solver)
        job.monitor = solver.ProgressMonitor(pass_results=True)
        pipeline.work(solver, job, solver.CancelToken())
        live = pipeline.LiveResult(bpy.context)
        live.show(bpy.context, job, job.monitor.take_pass_result())
        shown = full_state(scene)
        stats = pipeline.conclude(bpy.context, job, live)
        self.assertEqual(stats.elements, job.result.stats["leaves"])
        after = full_state(scene)
        self.assertEqual(after["result meshes"], shown["result meshes"], "the final result was the last pass")
        self.assertFalse([o for o in bpy.data.objects if o.name.endswith("(previous radiosity result)")])

    def test_a_solve_that_succeeds_is_not_rolled_back(self):
        scene = open_scene("cube")
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        first = full_state(scene)
        scene.radiosity.oracle = 'STANDARD'
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        second = full_state(scene)
        # Same objects and names; new meshes' contents (another oracle refines otherwise).
        self.assertEqual(sorted(first["result meshes"]), sorted(second["result meshes"]))
        self.assertNotEqual(first["result meshes"], second["result meshes"])
        self.assertFalse([o for o in bpy.data.objects if o.name.endswith("(previous radiosity result)")])


if __name__ == "__main__":
    unittest.main()
