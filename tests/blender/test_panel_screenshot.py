"""Screenshots of the Radiosity panel in a real window, written under the build folder.

Background Blender draws nothing, so this test starts a second Blender with a
window on a virtual X display (xvfb-run, as test_interactive.py does), in the
1280x800 window whose Properties editor is DEFAULT_REGION_WIDTH wide (the
width layout_check measures labels at), and runs panel_screenshot.py there:
BUILD/screenshots/panel.png (after a solve, Solve at the top), panel_end.png
(the statistics), panel_progress.png (a solve running: the progress bar; a
result object selected: the warning), window.png and search.png (F3 search for
"radiosity"). They are for looking at; the test checks that they were written
and that the window's Properties editor has the width the label checks assume.
Skipped when xvfb-run is not installed, and in bpy (Blender as a Python module),
which has no windows.
"""

import json
import os
import shutil
import subprocess
import sys
import unittest

import bpy

from layout_check import DEFAULT_REGION_WIDTH
from test_solve import ADDON_DIR, build_file

HERE = os.path.dirname(os.path.abspath(__file__))
SCREENSHOTS = os.path.join(os.path.dirname(ADDON_DIR), "screenshots")  # BUILD/screenshots
FILES = ("panel.png", "panel_end.png", "panel_progress.png", "window.png", "search.png", "sidebar.png")


@unittest.skipIf(shutil.which("xvfb-run") is None, "xvfb-run not installed (apt-get install xvfb libgl1-mesa-dri)")
@unittest.skipIf("blender_cli" in sys.modules, "bpy (Blender as a Python module) has no windows")
class PanelScreenshotTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        for name in FILES:
            path = os.path.join(SCREENSHOTS, name)
            if os.path.exists(path):
                os.remove(path)
        cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x800x24", bpy.app.binary_path, "--factory-startup",
               "--enable-event-simulate", build_file("cube"), "--python",
               os.path.join(HERE, "panel_screenshot.py"), "--", ADDON_DIR, SCREENSHOTS]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300, stdin=subprocess.DEVNULL)
        lines = [l for l in proc.stdout.splitlines() if l.startswith("RESULT ")]
        cls.output = proc.stdout[-3000:] + proc.stderr[-3000:]
        cls.result = json.loads(lines[-1][len("RESULT "):]) if lines else None

    def setUp(self):
        self.assertIsNotNone(self.result, self.output)

    def test_screenshots_written(self):
        self.assertEqual(sorted(os.path.basename(f) for f in self.result["files"]), sorted(FILES))
        for name in FILES:
            image = bpy.data.images.load(os.path.join(SCREENSHOTS, name))
            try:
                self.assertGreater(image.size[0], 100, name)
                self.assertGreater(image.size[1], 300, name)
            finally:
                bpy.data.images.remove(image)
        print("[summary] panel screenshots in %s" % SCREENSHOTS)

    def test_sidebar_has_a_radiosity_tab(self):
        # Drawn in the window's sidebar once its tab was chosen (Ctrl+Wheel over it).
        self.assertGreater(self.result.get("sidebar_drawn", 0), 0)

    def test_properties_width_is_the_one_labels_are_checked_at(self):
        self.assertEqual(self.result["region"][0], DEFAULT_REGION_WIDTH)

    def test_result_objects_not_selectable_in_the_window(self):
        self.assertGreater(self.result["results"], 0)
        self.assertEqual(self.result["selectable"], [])

    def test_progress_bar_path(self):
        # 3.4 has no UILayout.progress: the panel's own bar is what panel_progress.png shows.
        self.assertEqual(self.result["progress_api"], "progress" in bpy.types.UILayout.bl_rna.functions)


if __name__ == "__main__":
    unittest.main()
