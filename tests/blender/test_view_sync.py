"""The 3D views' shading follows the result through Solve, Toggle, Remove,
Undo and Redo (addon/ui/view_sync.py, result_state.sync_views).

Undo takes the scene back but not the screens: before view_sync, undoing a
first solve left every view flat-shaded by the colour attribute (the originals
drew flat white), and undoing Remove Result brought the result back in Studio
lighting (grey). Here the undo stack is driven headless (memfile undo works in
background Blender) and every 3D view's shading read after each step.
"""

import unittest

import bpy

from radiosity.write import result_state
from test_solve import open_scene


def shadings():
    """(colour type, lighting, back-face culling) of every 3D view."""
    return [(s.shading.color_type, s.shading.light, s.shading.show_backface_culling)
            for screen in bpy.data.screens for area in screen.areas for s in area.spaces
            if s.type == 'VIEW_3D']


def step(message, operator):
    """Runs `operator` as the user would: one undo step named `message`."""
    result = operator()
    bpy.ops.ed.undo_push(message=message)
    return result


class ViewsFollowTheResult(unittest.TestCase):
    def setUp(self):
        open_scene("cube")
        self.scene = bpy.context.scene
        self.before = shadings()
        self.assertTrue(self.before, "no 3D view to check")
        bpy.ops.ed.undo_push(message="opened")

    def shown(self):
        """The shading every view has while the result is shown."""
        views = shadings()
        self.assertTrue(all(c in {'VERTEX', 'ATTRIBUTE'} and light == 'FLAT' and cull
                            for c, light, cull in views), views)

    def originals(self):
        self.assertEqual(shadings(), self.before)

    def test_solve_undo_redo_remove_undo(self):
        self.assertEqual(step("solve", bpy.ops.radiosity.solve), {'FINISHED'})
        self.assertTrue(result_state.result_shown(bpy.context.scene))
        self.shown()
        bpy.ops.ed.undo()
        self.assertFalse(result_state.result_objects(bpy.context.scene))
        self.originals()
        bpy.ops.ed.redo()
        self.assertTrue(result_state.result_shown(bpy.context.scene))
        self.shown()
        self.assertEqual(step("remove", bpy.ops.radiosity.clear), {'FINISHED'})
        self.assertFalse(result_state.result_objects(bpy.context.scene))
        self.originals()
        bpy.ops.ed.undo()
        self.assertTrue(result_state.result_shown(bpy.context.scene))
        self.shown()

    def test_toggle_and_its_undo(self):
        step("solve", bpy.ops.radiosity.solve)
        step("toggle", bpy.ops.radiosity.toggle_result)
        self.assertFalse(result_state.result_shown(bpy.context.scene))
        self.originals()
        bpy.ops.ed.undo()
        self.assertTrue(result_state.result_shown(bpy.context.scene))
        self.shown()

    def test_remove_is_offered_only_with_something_to_remove(self):
        self.assertFalse(bpy.ops.radiosity.clear.poll())
        step("solve", bpy.ops.radiosity.solve)
        self.assertTrue(bpy.ops.radiosity.clear.poll())
        step("remove", bpy.ops.radiosity.clear)
        self.assertFalse(bpy.ops.radiosity.clear.poll())

    def test_toggle_icon_shows_the_state(self):
        from radiosity.ui import panels
        step("solve", bpy.ops.radiosity.solve)
        self.assertEqual(panels.toggle_icon(bpy.context.scene), 'HIDE_OFF')
        step("toggle", bpy.ops.radiosity.toggle_result)
        self.assertEqual(panels.toggle_icon(bpy.context.scene), 'HIDE_ON')


if __name__ == "__main__":
    unittest.main()
