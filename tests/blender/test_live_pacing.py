"""The pacing of the live result (addon/ui/live_pacing.py): a pass is shown only
once the last one's bake and redraws cost at most the display's share of the
time since; the 3D views' draw handlers it adds are removed again."""

import unittest

import bpy

from radiosity.ui import live_pacing


class LivePacingTest(unittest.TestCase):
    def setUp(self):
        self.now = 100.0  # the pacer's clock, moved by the tests
        self.pacing = live_pacing.LivePacing(share=0.2, clock=lambda: self.now)
        self.addCleanup(self.pacing.close)

    def test_the_first_pass_is_always_shown(self):
        self.assertTrue(self.pacing.may_show())

    def test_the_next_pass_waits_for_the_cost_to_be_a_share_of_the_time(self):
        self.pacing.shown(began=10.0, ended=10.1)  # a 0.1 s bake
        self.assertFalse(self.pacing.may_show(now=10.45))  # 0.1 s of 0.45 s: 22 %
        self.assertTrue(self.pacing.may_show(now=10.55))  # 0.1 s of 0.55 s: 18 %

    def test_redraws_after_a_pass_count_in_its_cost(self):
        self.pacing.shown(began=self.now, ended=self.now)
        for _ in range(3):  # as Blender calls the handlers around each redraw
            self.pacing.draw_begins()
            self.now += 0.02
            self.pacing.draw_ends()
            self.now += 0.01
        self.assertAlmostEqual(self.pacing.cost, 0.06)
        self.assertFalse(self.pacing.may_show())  # 0.06 s of 0.09 s
        self.now += 0.2
        self.assertFalse(self.pacing.may_show())  # 0.06 s of 0.29 s: 21 %
        self.now += 0.02
        self.assertTrue(self.pacing.may_show())  # 0.06 s of 0.31 s: 19 %

    def test_draws_before_the_first_pass_cost_nothing(self):
        self.pacing.draw_begins()
        self.pacing.draw_ends()
        self.assertEqual(self.pacing.cost, 0.0)

    def test_close_removes_its_draw_handlers(self):
        pacing = live_pacing.LivePacing()
        handlers = list(pacing._handlers)
        pacing.close()
        pacing.close()  # twice is harmless (the operator's cancel and stop both close)
        for handler in handlers:
            with self.assertRaises(ValueError):
                bpy.types.SpaceView3D.draw_handler_remove(handler, 'WINDOW')


if __name__ == "__main__":
    unittest.main()
