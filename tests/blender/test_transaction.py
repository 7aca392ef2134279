"""A solve that fails at any step (the export, or writing its result) leaves the
scene exactly as it was, the previous result included (addon/result_state.py).

Each step the operator takes after the native solve (replacing the result
objects, hiding the originals, showing the results, writing the attribute on
the originals, switching the 3D views to attribute colours) is made to fail
after doing its work, the worst case; the scene is then compared with the
scene before the solve, down to the attribute values and the result meshes.
"""

import unittest

import bpy
import numpy as np

from radiosity import bake, bake_materials
from test_addon import scene_snapshot
from test_solve import open_scene

# The steps each output mode takes after the native solve (operators.py, _finish).
STEPS = {
    'REFINED': ("write_refined", "hide_originals", "show_results", "set_viewport_attribute_colour"),
    'LIGHTING': ("write_refined", "hide_originals", "show_results", "set_viewport_attribute_colour"),
    'BOTH': ("write_refined", "hide_originals", "show_results", "write_original", "set_viewport_attribute_colour"),
    'ORIGINAL': ("restore_originals", "write_original", "set_viewport_attribute_colour"),
}


class InjectedFailure(RuntimeError):
    pass


def failing_after(function):
    def step(*args, **kwargs):
        function(*args, **kwargs)
        raise InjectedFailure("injected after %s" % function.__name__)
    return step


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
                              for o in bake.result_objects(scene)}
    state["tags"] = {o.name: dict((k, str(o[k])) for k in o.keys() if k.startswith("radiosity"))
                     for o in scene.objects}
    state["shading"] = [s.shading.color_type for scr in bpy.data.screens for a in scr.areas
                        for s in a.spaces if s.type == 'VIEW_3D']
    return state


class FailingStepsChangeNothing(unittest.TestCase):
    def check(self, previous_output, output):
        for step in STEPS[output]:
            with self.subTest(previous=previous_output, output=output, step=step):
                scene = open_scene("cube")
                if previous_output:
                    scene.radiosity.output = previous_output
                    self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                before = full_state(scene)
                scene.radiosity.output = output
                scene.radiosity.oracle = 'STANDARD'
                original = getattr(bake, step)
                setattr(bake, step, failing_after(original))
                try:
                    # The operator reports the error, which bpy.ops raises.
                    with self.assertRaisesRegex(RuntimeError, "injected after " + step):
                        bpy.ops.radiosity.solve()
                finally:
                    setattr(bake, step, original)
                self.assertEqual(full_state(scene), before)

    def test_first_solve(self):
        self.check(None, 'BOTH')

    def test_re_solve_keeps_the_previous_result(self):
        self.check('BOTH', 'BOTH')

    def test_re_solve_in_another_output_mode(self):
        self.check('REFINED', 'ORIGINAL')
        self.check('ORIGINAL', 'LIGHTING')

    def test_a_failing_export_changes_nothing(self):
        from radiosity import export
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
