"""How often an interactive solve may show a pass: the display's share of the time.

Showing a pass costs a bake and then the 3D views' redraws, and the redraws
can cost far more than the bake: the viewport's anti-aliasing draws each
change up to 8 times, which on a GPU is nothing and under software OpenGL
(virtual machines, remote desktops, Xvfb) takes about 0.2 s per draw of a
furnished room, on the cores the solve needs. The pacer measures both costs
(the draws with 3D view draw handlers) and lets the next pass show only once
the last one's cost is at most `share` of the time since it was shown, so the
solve keeps the rest of the machine whatever the display costs. The final
result is always shown (pipeline.LiveResult.finish).
"""

import time

import bpy

# The largest fraction of the wall time the live result may take.
DISPLAY_SHARE = 0.15


class LivePacing:
    """Decides when the next pass may be shown; measures what showing costs."""

    def __init__(self, share=DISPLAY_SHARE, clock=time.perf_counter):
        self.share = share
        self.clock = clock  # seconds; the draws are timed on it
        self.shown_at = None  # the clock when the last pass was shown
        self.cost = 0.0  # seconds its bake and the draws since took
        self._draw_started = None
        self._handlers = [
            bpy.types.SpaceView3D.draw_handler_add(self.draw_begins, (), 'WINDOW', 'PRE_VIEW'),
            bpy.types.SpaceView3D.draw_handler_add(self.draw_ends, (), 'WINDOW', 'POST_PIXEL'),
        ]

    def draw_begins(self):
        self._draw_started = self.clock()

    def draw_ends(self):
        if self._draw_started is not None and self.shown_at is not None:
            self.cost += self.clock() - self._draw_started
        self._draw_started = None

    def may_show(self, now=None):
        """Whether a pass may be shown now: the first always may."""
        if self.shown_at is None:
            return True
        now = self.clock() if now is None else now
        return self.cost <= self.share * (now - self.shown_at)

    def shown(self, began, ended):
        """A pass was baked from `began` to `ended` (on the clock); its draws follow."""
        self.shown_at = began
        self.cost = ended - began

    def close(self):
        for handler in self._handlers:
            bpy.types.SpaceView3D.draw_handler_remove(handler, 'WINDOW')
        self._handlers = []
