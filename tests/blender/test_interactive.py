"""The interactive solve (invoke: worker thread, modal timer, ESC) in a real window.

Background Blender has no window, so invoke falls back to the synchronous
solve there. This test starts a second Blender with a window on a virtual X
display (xvfb-run, Debian packages xvfb and libgl1-mesa-dri), invokes the
operator in its 3D view and, in some runs, presses Esc on that display
(xdotool). Skipped when xvfb-run or xdotool is not installed, and in bpy
(Blender as a Python module, run through tools/blender_cli.py), which has no
windows at all.
"""

import json
import os
import shutil
import subprocess
import sys
import threading
import time
import unittest

import bpy

from radiosity import native, pipeline
from test_solve import ADDON_DIR, build_file, open_scene

HERE = os.path.dirname(os.path.abspath(__file__))
SHOTS = os.path.join(os.path.dirname(ADDON_DIR), "screenshots")  # <build>/screenshots
os.makedirs(SHOTS, exist_ok=True)


def headless_timeline(name, quality, marks, passes_after):
    """A headless solve of scene `name` on a worker thread, as the window's
    runs (same pipeline, a ProgressMonitor polled every 5 ms): {pass: (seconds
    after the start when it completed, its leaves)} and {mark: leaves refined
    by then}. Cancelled once `passes_after` seconds have passed and a pass
    has completed since, to spare the rest."""
    open_scene(name).radiosity.quality = quality
    solver = native.load()
    started = time.perf_counter()
    job = pipeline.prepare(bpy.context, solver, started)
    job.monitor = solver.ProgressMonitor()
    token = solver.CancelToken()
    worker = threading.Thread(target=pipeline.work, args=(solver, job, token))
    worker.start()
    completed, leaves_after = {}, {}
    while worker.is_alive():
        progress, now = job.monitor.progress(), time.perf_counter() - started
        if progress:
            for mark in marks:
                if now >= mark and mark not in leaves_after:
                    leaves_after[mark] = progress.get("leaves", 0)
            if progress.get("phase") == "pass" and progress["pass"] not in completed:
                completed[progress["pass"]] = (now, progress["leaves"])
                if now > passes_after and len(leaves_after) == len(marks):
                    token.cancel()
        time.sleep(0.005)
    worker.join()
    return completed, leaves_after


@unittest.skipIf(shutil.which("xvfb-run") is None, "xvfb-run not installed (apt-get install xvfb libgl1-mesa-dri)")
@unittest.skipIf(shutil.which("xdotool") is None, "xdotool not installed (apt-get install xdotool)")
@unittest.skipIf("blender_cli" in sys.modules, "bpy (Blender as a Python module) has no windows")
class InteractiveSolveTest(unittest.TestCase):
    def run_window(self, scene, mode, shots=None):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
               build_file(scene), "--python",
               os.path.join(HERE, "interactive_solve.py"), "--", ADDON_DIR, mode] + ([shots] if shots else [])
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
        lines = [l for l in proc.stdout.splitlines() if l.startswith("RESULT ")]
        self.assertTrue(lines, proc.stdout[-3000:] + proc.stderr[-3000:])
        return json.loads(lines[-1][len("RESULT "):])

    def test_invoke_runs_modal_and_bakes(self):
        r = self.run_window("cube", "run")
        self.assertEqual(r["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(r["valid"])
        self.assertEqual(r["status"], "Converged")
        self.assertEqual(r["results"], 8)
        self.assertTrue(r["hidden"])
        self.assertTrue(set(r["shading"]) <= {"VERTEX", "ATTRIBUTE"}, r["shading"])

    def test_passes_show_live_with_a_steady_progress(self):
        # A solve of a furnished room takes seconds: its passes reach the
        # viewport while it runs, the progress only moves forward, and a UI
        # timer keeps running.
        shot = os.path.join(SHOTS, "solve_in_progress.png")
        if os.path.exists(shot):
            os.remove(shot)
        r = self.run_window("full_office", "run", SHOTS)
        self.assertTrue(r["valid"], r)
        self.assertGreaterEqual(r["updates_while_running"], 1, r)
        self.assertTrue(os.path.exists(shot), r)  # the window as a pass was shown
        fractions = r["fractions"]
        self.assertGreater(len(fractions), 3, r)
        self.assertEqual(fractions, sorted(fractions), "the progress went back")
        self.assertGreater(r["final_polygons"], 0)
        print("interactive full_office: %.1f s, UI timer %.1f Hz (asked 20), %d live updates"
              % (r["running_seconds"], r["timer_hz"], r["updates_while_running"]))
        # The timer's rate is printed, not asserted: under the software OpenGL
        # the tests run with, each redraw of the window costs tens of
        # milliseconds and bounds it (measured 7-8.5 Hz of the 20 asked).

    def test_two_sided_faces_do_not_speckle(self):
        # Each side of a two-sided face is its own polygon, a hair in front of
        # the other: in Solid view the two fight for the depth buffer and closed
        # objects speckle, unless back faces are culled (View Result does).
        # Speckle: pixels that differ from the median of their 3 x 3 neighbours
        # by more than 0.08 in luminance, inside the camera frame (edges count
        # too, so a clean view is not 0).
        import matplotlib.image as mpimg
        import numpy as np
        from numpy.lib.stride_tricks import sliding_window_view
        speckle = {}
        for mode in ("cull", "nocull"):
            out = os.path.join(SHOTS, "full_office_solid_%s.png" % mode)
            if os.path.exists(out):
                os.remove(out)
            cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
                   build_file("full_office"), "--python", os.path.join(HERE, "viewport_screenshot.py"), "--",
                   ADDON_DIR, out, mode]
            proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
            self.assertTrue(os.path.exists(out), proc.stdout[-2000:] + proc.stderr[-2000:])
            image = mpimg.imread(out)[..., :3].astype(float)
            h, w = image.shape[:2]
            lum = image[h // 4:3 * h // 4, w // 4:3 * w // 4] @ [0.2126, 0.7152, 0.0722]
            window = sliding_window_view(np.pad(lum, 1, mode='edge'), (3, 3)).reshape(*lum.shape, 9)
            speckle[mode] = float(np.mean(np.abs(lum - np.median(window, axis=-1)) > 0.08))
        print("speckled pixels in Solid view: %.4f culled, %.4f not" % (speckle["cull"], speckle["nocull"]))
        self.assertLess(speckle["cull"], 0.6 * speckle["nocull"], speckle)

    def test_escape_after_seconds_keeps_what_a_headless_solve_keeps(self):
        # The solve in a window must be as fast as a headless one: the add-on's
        # polling, status, live passes and redraws must not starve it. Esc keeps
        # the last complete pass, a step in time. From a headless solve of the
        # same scene, measured just before, Esc comes at 1.25 times the time
        # of a pass completed after 1 s (the latest whose next pass comes
        # later still): the window keeps that pass only if it runs at least
        # 80 % as fast. Fixed times would not do: a faster solver moves the
        # passes (at 4 s there was no pass left to keep after one speed-up).
        # Two timings compared on a shared machine: a burst of other load during
        # one of them fails it, so a second attempt (both measured again) may
        # pass; a window truly slower fails both.
        for attempt in range(2):
            completed, headless_after = headless_timeline("full_office", 1.0, (2.0, 4.0, 6.0), passes_after=4.0)
            times = sorted((t, leaves) for t, leaves in completed.values())
            self.assertGreaterEqual(len(times), 2, completed)
            keepable = [i for i in range(len(times) - 1)
                        if times[i][0] >= 1.0 and times[i][0] / 0.8 < times[i + 1][0]]
            self.assertTrue(keepable, times)
            kept_pass = keepable[-1]
            esc = times[kept_pass][0] / 0.8
            headless_kept = times[kept_pass][1]
            r = self.run_window("full_office", "cancel_after:%.2f" % esc)
            print("Esc after %.1f s: the window kept %d elements, headless %d; refined after 2/4/6 s: "
                  "window %s, headless %s" % (esc, r["elements"], headless_kept,
                                              "/".join(str(r["leaves_after"].get(str(m), "-")) for m in (2.0, 4.0, 6.0)),
                                              "/".join(str(headless_after.get(m, "-")) for m in (2.0, 4.0, 6.0))))
            self.assertEqual(r["status"], "Cancelled (last complete pass kept)", r)
            if r["elements"] >= 0.8 * headless_kept:
                break
        self.assertGreaterEqual(r["elements"], 0.8 * headless_kept, r)

    def test_escape_keeps_the_last_complete_pass(self):
        r = self.run_window("full_office", "cancel")
        self.assertEqual(r["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(r["valid"])
        self.assertEqual(r["status"], "Cancelled (last complete pass kept)")
        self.assertGreater(r["results"], 0)
        self.assertGreater(r["elements"], 0)


if __name__ == "__main__":
    unittest.main()
