"""The zips of `make package` (tools/package.py), installed as a user would, in this Blender.

Each test starts a second Blender of the same kind (bpy.app.binary_path) with a
clean, empty user folder (BLENDER_USER_RESOURCES, and BLENDER_USER_SCRIPTS for
3.x), installs a zip through Blender's own installer, enables it, builds the
bundled cube scene (scenes/), solves it and reports, as one JSON line: where
the add-on and its compiled module were loaded from, which shared libraries the
process mapped before and after, and the baked attribute's values; it also
renders the baked solution and a path-traced Cycles reference of the scene.
The tests assert that all of it came from the installed package, not from the
build tree or the system, and that the solution agrees with the reference as
test_cycles.py requires (its tolerances, quality and samples). This file is
the package-level check `make test` runs in the Blenders between the oldest
and the newest (tests/run_tests.py --check-blender).

One zip (tools/package.py: the folder radiosity/ with bl_info and the manifest)
through both of Blender's installers:
- the extension installer (Blender 4.2+): bpy.ops.extensions.package_install_files
  into the "user_default" repository. Skipped in Blenders without extensions.
- the add-on installer (Preferences > Add-ons > Install), in every Blender:
  bpy.ops.preferences.addon_install.
Either leaves one folder, radiosity/, in the user folder's add-ons or extensions
and nothing loose (the files of an extension laid out at the zip's top went loose
into 3.x's scripts/addons/, with no add-on to enable).
"""

import json
import os
import pathlib
import subprocess
import tempfile
import unittest

import bpy
import numpy as np

import radiosity
import render_compare as rc
import test_cycles
from solved_report import check_solved_and_baked

BUILD = pathlib.Path(radiosity.__file__).resolve().parents[2]   # <build>/addon/radiosity/__init__.py
ROOT = pathlib.Path(__file__).resolve().parents[2]
HERE = pathlib.Path(__file__).resolve().parent


def package_zip():
    """The zip in the build folder."""
    import tomllib
    manifest = tomllib.loads((BUILD / "addon" / "radiosity" / "blender_manifest.toml").read_text())
    path = BUILD / ("%s-%s-%s.zip" % (manifest["id"], manifest["version"],
                                      "_".join(manifest["platforms"]).replace("-", "_")))
    if not path.exists():
        raise AssertionError("%s not found: run `make package` (make test does)" % path)
    return path


def installed_entries(user):
    """What the installers put into the user folder's add-ons and extensions folders:
    their entries (but __pycache__ and the extension repository's own records)."""
    found = []
    for folder in ("scripts/addons", "extensions/user_default"):
        path = pathlib.Path(user) / folder
        if path.is_dir():
            found += ["%s/%s" % (folder, p.name) for p in sorted(path.iterdir())
                      if p.name != "__pycache__" and not p.name.startswith(".")]
    return found


def has_extensions():
    return hasattr(bpy.ops, "extensions") and "package_install_files" in dir(bpy.ops.extensions)


class InstalledPackageTest(unittest.TestCase):
    def install_and_solve(self, kind):
        """Run install_and_solve.py in a fresh Blender with an empty user folder; its report."""
        with tempfile.TemporaryDirectory(prefix="radiosity-user-") as user:
            env = dict(os.environ, BLENDER_USER_RESOURCES=user, BLENDER_USER_SCRIPTS=os.path.join(user, "scripts"),
                       BLENDER_USER_CONFIG=os.path.join(user, "config"))
            images = os.path.join(user, "images")
            os.mkdir(images)
            cmd = [bpy.app.binary_path, "-b", "--factory-startup", "--python-exit-code", "1",
                   "--python", str(HERE / "install_and_solve.py"), "--",
                   kind, str(package_zip()), str(ROOT / "scenes"), str(test_cycles.QUALITY),
                   str(test_cycles.REFERENCE_SAMPLES), images]
            proc = subprocess.run(cmd, env=env, capture_output=True, text=True, timeout=600,
                                  stdin=subprocess.DEVNULL)
            log = proc.stdout[-3000:] + proc.stderr[-3000:]
            lines = [line for line in proc.stdout.splitlines() if line.startswith("RESULT ")]
            self.assertEqual(proc.returncode, 0, log)
            self.assertTrue(lines, log)
            report = json.loads(lines[-1][len("RESULT "):])
            report["user"] = os.path.realpath(user)
            report["installed"] = installed_entries(user)
            report["solution"], report["reference"] = (np.load(os.path.join(images, name + ".npy"))
                                                       for name in ("solution", "reference"))
            return report

    def check(self, report):
        user = report["user"]
        inside = lambda path: os.path.realpath(path).startswith(user + os.sep)  # noqa: E731
        self.assertTrue(inside(report["addon_file"]), report["addon_file"])
        self.assertTrue(inside(report["module_file"]), report["module_file"])
        self.assertNotIn(str(BUILD), report["module_file"])
        # Whatever the add-on brought into the process came from the package: the
        # module itself (Embree and TBB are linked into it) and nothing from the machine.
        new = [p for p in report["libraries"] if p not in report["host_libraries"]]
        self.assertIn(os.path.realpath(report["module_file"]), [os.path.realpath(p) for p in new])
        self.assertFalse([p for p in new if not inside(p)], new)
        check_solved_and_baked(self, report)
        # The installed add-on's solution against the path-traced reference.
        mean_error, region_error, _, _ = rc.compare(report["solution"], report["reference"])
        print("[agreement] installed %s: mean %.1f %%, worst cell %.1f %% (%d elements)"
              % (report["module"], 100 * mean_error, 100 * region_error, report["elements"]), flush=True)
        self.assertLess(mean_error, test_cycles.MEAN_TOLERANCE)
        self.assertLess(region_error, test_cycles.REGION_TOLERANCE)

    @unittest.skipUnless(has_extensions(), "this Blender has no extensions (4.2+)")
    def test_zip_through_the_extension_installer(self):
        report = self.install_and_solve("extension")
        self.assertTrue(report["module"].startswith("bl_ext.user_default."), report["module"])
        self.assertEqual(report["installed"], ["extensions/user_default/radiosity"])
        self.check(report)

    def test_zip_through_the_addon_installer(self):
        # The same zip through the add-on installer, as in 3.x (and 4.2+'s
        # Add-ons > Install from Disk).
        report = self.install_and_solve("legacy")
        self.assertEqual(report["module"], "radiosity")
        self.assertEqual(report["installed"], ["scripts/addons/radiosity"])
        self.check(report)


if __name__ == "__main__":
    unittest.main()
