"""The interactive solve (invoke: worker thread, modal timer, ESC) in a real window.

Background Blender has no window, so invoke falls back to the synchronous
solve there. This test starts a second Blender with a window on a virtual X
display (xvfb-run, Debian packages xvfb and libgl1-mesa-dri), invokes the
operator in its 3D view and, in one run, sends ESC through the window's event
queue (--enable-event-simulate). Skipped when xvfb-run is not installed, and in
bpy (Blender as a Python module, run through tools/blender_cli.py), which has no
windows at all.
"""

import json
import os
import shutil
import subprocess
import sys
import unittest

import bpy

from test_solve import ADDON_DIR, build_file

HERE = os.path.dirname(os.path.abspath(__file__))


@unittest.skipIf(shutil.which("xvfb-run") is None, "xvfb-run not installed (apt-get install xvfb libgl1-mesa-dri)")
@unittest.skipIf("blender_cli" in sys.modules, "bpy (Blender as a Python module) has no windows")
class InteractiveSolveTest(unittest.TestCase):
    def run_window(self, scene, mode):
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
               "--enable-event-simulate", build_file(scene), "--python",
               os.path.join(HERE, "interactive_solve.py"), "--", ADDON_DIR, mode]
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

    def test_escape_keeps_the_last_complete_pass(self):
        r = self.run_window("full_office", "cancel")
        self.assertEqual(r["invoke"], ["RUNNING_MODAL"])
        self.assertTrue(r["valid"])
        self.assertEqual(r["status"], "Cancelled (last complete pass kept)")
        self.assertGreater(r["results"], 0)
        self.assertGreater(r["elements"], 0)


if __name__ == "__main__":
    unittest.main()
