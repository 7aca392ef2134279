"""The compiled `_radiosity` module loads in plain Python and says which version it is.

Run by tests/run_tests.py with build/addon/radiosity on sys.path, under Debian's
/usr/bin/python3 (the interpreter Blender runs), without Blender, and under each
CPython of --native-python (3.10, 3.13), which loads the module built for it.
"""

import pathlib
import re
import sys
import unittest

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10 (Blender 3.6 to 4.1): tomllib's original
    import tomli as tomllib

ROOT = pathlib.Path(__file__).resolve().parents[2]


def project_version():
    """VERSION of project() in the top-level CMakeLists.txt, the one source of truth."""
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    return re.search(r"project\(\s*radiosity\s+VERSION\s+([0-9.]+)", text).group(1)


class ModuleTest(unittest.TestCase):
    def test_imports_from_the_assembled_addon(self):
        import _radiosity

        path = pathlib.Path(_radiosity.__file__)
        self.assertEqual(path.parent.name, "radiosity", "expected build/addon/radiosity/")
        # Windows (the Windows module, run under Wine): _radiosity.cp311-win_amd64.pyd
        tag = ("cp%d%d-" if sys.platform == "win32" else "cpython-%d%d") % sys.version_info[:2]
        self.assertIn(tag, path.name, "module built for another Python than this one")

    def test_addon_sources_compile_in_this_python(self):
        """Every Python file of the assembled add-on is valid in this interpreter's
        version (3.10 for Blender 3.6 to 4.0, 3.13 for 5.1 and later)."""
        import _radiosity

        sources = sorted(pathlib.Path(_radiosity.__file__).parent.glob("*.py"))
        self.assertIn("__init__.py", [p.name for p in sources])
        for path in sources:
            with self.subTest(path.name):
                compile(path.read_text(encoding="utf-8"), str(path), "exec")

    def test_version_matches_project_and_addon(self):
        import _radiosity

        self.assertIsInstance(_radiosity.__version__, str)
        self.assertRegex(_radiosity.__version__, r"^\d+\.\d+\.\d+$")
        self.assertEqual(_radiosity.__version__, project_version())
        # The manifest is copied next to the module; a release bumps all of them.
        manifest = pathlib.Path(_radiosity.__file__).parent / "blender_manifest.toml"
        with open(manifest, "rb") as f:
            self.assertEqual(tomllib.load(f)["version"], _radiosity.__version__)

    def test_addon_defaults_are_the_modules(self):
        """The add-on's settings start from solver_defaults.json, written by the
        build from the same SolveOptions{} the module's solve() defaults to."""
        import json

        import _radiosity

        packaged = pathlib.Path(_radiosity.__file__).with_name("solver_defaults.json")
        defaults = json.loads(_radiosity.DEFAULTS_JSON)
        self.assertEqual(json.loads(packaged.read_text()), defaults)
        self.assertEqual(defaults["oracles"], ["standard", "perceptual", "gradient", "noticeable"])
        self.assertIn(defaults["oracle"], defaults["oracles"])
        for name in defaults["oracles"]:
            self.assertGreater(_radiosity.quality_threshold(name, 0.5), 0.0)
        self.assertIn(defaults["visibility"], ("exact", "sampled"))
        self.assertTrue(0.0 < defaults["quality"] <= 1.0)
        self.assertTrue(1 <= defaults["rays"] <= defaults["max_rays"])

    def test_has_docstring(self):
        import _radiosity

        self.assertTrue(_radiosity.__doc__)


if __name__ == "__main__":
    unittest.main()
