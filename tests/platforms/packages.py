"""What the platform tests share: the zips of one platform (tools/package.py), unpacked,
and the checks every zip gets whatever its platform (contents and manifest).

The build folder is the one whose assembled add-on (BUILD/addon/radiosity) is on
sys.path, as tests/run_tests.py gives it; the Linux module is not imported.
"""

import sys
import tempfile
import tomllib
import unittest
import zipfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "tools"))
import cpython  # noqa: E402  (tools/cpython.py: the Python versions built for)
import cross_build  # noqa: E402  (tools/cross_build.py: module file names)
import package  # noqa: E402  (tools/package.py: zip names)



def _assembled_addon():
    """BUILD/addon/radiosity: the folder on sys.path that holds the assembled add-on."""
    for entry in sys.path:
        folder = Path(entry).resolve()
        if folder.parts[-2:] == ("addon", "radiosity") and (folder / "blender_manifest.toml").exists():
            return folder
    raise AssertionError("no BUILD/addon/radiosity on sys.path (tests/run_tests.py puts it there)")


ADDON = _assembled_addon()
BUILD = ADDON.parent.parent


def manifest():
    return tomllib.loads((ADDON / package.MANIFEST).read_text())


def zip_path(platform):
    path = BUILD / package.zip_name(manifest(), platform)
    if not path.exists():
        raise AssertionError("%s not found: run `make test-platforms` (it builds the %s modules and "
                             "runs `make package`)" % (path, platform))
    return path


class UnpackedZip(unittest.TestCase):
    """Unpacks PLATFORM's zip, whose one folder radiosity/ becomes self.root (once per class)."""
    PLATFORM = None

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="radiosity-%s-" % cls.PLATFORM)
        with zipfile.ZipFile(zip_path(cls.PLATFORM)) as zf:
            zf.extractall(cls.tmp.name)
        cls.root = Path(cls.tmp.name).resolve() / "radiosity"   # the zip's one folder (tools/package.py)
        cls.modules = {minor: cls.root / ("_radiosity" + cross_build.suffix(cls.PLATFORM, minor))
                       for minor in cpython.VERSIONS}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()


class PackageChecks:
    """What every platform's zip is checked for (mixed into an UnpackedZip)."""

    def test_zips_hold_the_addon_and_one_module_per_python(self):
        python_files = sorted(p.relative_to(ADDON).as_posix() for p in ADDON.rglob("*.py")
                              if "__pycache__" not in p.parts)  # the sub-packages too
        prefix = package.FOLDER  # one folder: the add-on in 3.x, the extension in 4.2+
        with zipfile.ZipFile(zip_path(self.PLATFORM)) as zf:
            names = zf.namelist()
        binaries = sorted(n[len(prefix):] for n in names if "_radiosity." in n)
        self.assertEqual(binaries, sorted(p.name for p in self.modules.values()))
        self.assertFalse([n for n in names if "linux-gnu" in n or n.startswith(prefix + "libs/")], names)
        self.assertTrue(all(n.startswith(prefix) for n in names), names)
        self.assertLessEqual(set(prefix + p for p in python_files), set(names))
        self.assertIn(prefix + package.MANIFEST, names)
        print("[package] %s: %s" % (self.PLATFORM, ", ".join(
            "%s (%.1f MB)" % (p.name, p.stat().st_size / 1e6) for p in self.modules.values())), flush=True)

    def test_manifest_lists_this_platform(self):
        found = tomllib.loads((self.root / package.MANIFEST).read_text())
        self.assertEqual(found["platforms"], [self.PLATFORM])
        self.assertEqual({k: v for k, v in found.items() if k != "platforms"},
                         {k: v for k, v in manifest().items() if k != "platforms"})
