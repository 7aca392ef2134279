"""The packaged module's dependencies (`make package`, tools/package.py), checked as
auditwheel checks a wheel for the manylinux_2_28 policy: with readelf, objdump and
ldd on the files inside the zip.

- Every shared object in the package needs only libraries inside the package or
  in the allowed system set (glibc's libraries, libstdc++, libgcc_s, libm, the
  dynamic loader), and each of them resolves, unpacked anywhere, with no
  LD_LIBRARY_PATH: nothing else comes from the machine (OpenImageIO is gone).
  The portable build (native/portable) links Embree, TBB and libc++ into the
  module, so it needs glibc alone.
- No libpython: the interpreter that imports the module provides it.
- One module per CPython version of tools/cpython.py (3.10, 3.11, 3.13), each
  named with its version's suffix; the one of the Python running the test loads.
- The symbol versions they require from the system are within manylinux_2_28:
  glibc 2.28, GLIBCXX 3.4.24, CXXABI 1.3.11, GCC 7 (Blender's own Linux builds
  need glibc 2.28 too). A local build made with PORTABLE=OFF (Debian's Embree
  and TBB, glibc 2.34) fails here, naming the symbols.
- The module imports from the unpacked package in plain Python and maps only
  the package's and the allowed libraries.
"""

import os
import re
import subprocess
import sys
import tempfile
import unittest
import zipfile
from pathlib import Path

try:
    import tomllib
except ModuleNotFoundError:  # Python 3.10 (Blender 3.6 to 4.1): tomllib's original
    import tomli as tomllib

import _radiosity

ADDON = Path(_radiosity.__file__).resolve().parent          # <build>/addon/radiosity
BUILD = ADDON.parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import cpython  # noqa: E402  (the CPython versions the modules are built for)

# Sonames the package may take from the system (auditwheel's manylinux whitelist,
# less what the module does not use).
ALLOWED = {"libc.so.6", "libm.so.6", "libdl.so.2", "librt.so.1", "libpthread.so.0",
           "libstdc++.so.6", "libgcc_s.so.1", "ld-linux-x86-64.so.2", "linux-vdso.so.1"}
MANYLINUX_2_28 = {"GLIBC": (2, 28), "GLIBCXX": (3, 4, 24), "CXXABI": (1, 3, 11), "GCC": (7, 0, 0)}


def package_zip():
    manifest = tomllib.loads((ADDON / "blender_manifest.toml").read_text())
    path = BUILD / ("%s-%s-%s.zip" % (manifest["id"], manifest["version"],
                                       "_".join(manifest["platforms"]).replace("-", "_")))
    if not path.exists():
        raise AssertionError("%s not found: run `make package` (make test does)" % path)
    return path


def stem(path):
    """A library's name without version: /usr/lib/libstdc++.so.6.0.30 -> libstdc++."""
    return os.path.basename(path).split(".so")[0]


def is_elf(path):
    with open(path, "rb") as f:
        return f.read(4) == b"\x7fELF"


def readelf_dynamic(path):
    out = subprocess.run(["readelf", "-d", "-W", str(path)], capture_output=True, text=True, check=True).stdout
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+?)\]", out)
    runpath = re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library r(?:un)?path: \[(.+?)\]", out)
    return needed, runpath


def required_versions(path):
    """{(family, version tuple): [symbols]} of the versioned symbols `path` needs from others."""
    out = subprocess.run(["objdump", "-T", str(path)], capture_output=True, text=True, check=True).stdout
    found = {}
    for line in out.splitlines():
        match = re.search(r"\*UND\*\s+\S+\s+(?:\(|)(GLIBC|GLIBCXX|CXXABI|GCC)_([0-9.]+)\)?\s+(\S+)", line)
        if match:
            family, version, symbol = match.groups()
            key = (family, tuple(int(x) for x in version.split(".")))
            found.setdefault(key, []).append(symbol)
    return found


def ldd(path):
    """{soname: resolved path or None} as the dynamic loader resolves `path` alone."""
    env = {k: v for k, v in os.environ.items() if k != "LD_LIBRARY_PATH"}
    out = subprocess.run(["ldd", str(path)], capture_output=True, text=True, env=env, check=True).stdout
    resolved = {}
    for line in out.splitlines():
        line = line.strip()
        if "=>" in line:
            name, target = (part.strip() for part in line.split("=>", 1))
            resolved[name] = None if target.startswith("not found") else target.split(" (")[0]
        elif line:
            name = line.split(" (")[0]
            resolved[os.path.basename(name)] = name
    return resolved


class PackagedModuleTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory(prefix="radiosity-package-")
        with zipfile.ZipFile(package_zip()) as zf:
            cls.names = zf.namelist()
            zf.extractall(cls.tmp.name)
        cls.root = Path(cls.tmp.name).resolve() / "radiosity"  # the zip's one folder (tools/package.py)
        cls.elves = sorted(p for p in cls.root.rglob("*") if p.is_file() and is_elf(p))
        for path in cls.elves:   # zipfile drops the mode bits of what it extracts
            path.chmod(0o755)

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_one_folder_for_every_blender(self):
        # One top-level folder with bl_info's __init__.py and the manifest: Blender
        # 3.x's add-on installer makes it the add-on radiosity (files at the zip's
        # top went loose into scripts/addons/), 4.2+'s extension installer finds
        # the manifest in it (test_package.py in tests/blender installs it in both).
        self.assertEqual({n.split("/")[0] for n in self.names}, {"radiosity"}, self.names)
        self.assertIn("radiosity/__init__.py", self.names)
        self.assertIn("radiosity/blender_manifest.toml", self.names)
        self.assertIn("bl_info", (self.root / "__init__.py").read_text())

    def test_package_has_the_module_and_its_libraries(self):
        names = sorted(p.relative_to(self.root).as_posix() for p in self.elves)
        modules = {"_radiosity.cpython-%s-x86_64-linux-gnu.so" % v.replace(".", "") for v in cpython.VERSIONS}
        self.assertEqual({n for n in names if n.startswith("_radiosity.")}, modules, names)
        self.assertIn(Path(_radiosity.__file__).name, modules)
        self.assertFalse([n for n in names if "image_metric" in n or "OpenImageIO" in n], names)
        print("[package] %s" % ", ".join("%s (%.1f MB)" % (n, (self.root / n).stat().st_size / 1e6)
                                         for n in names), flush=True)

    def test_every_dependency_is_in_the_package_or_allowed(self):
        packaged = {p.name for p in self.elves}
        for path in self.elves:
            needed, runpath = readelf_dynamic(path)
            self.assertFalse([n for n in needed if n.startswith("libpython")], path)
            outside = [n for n in needed if n not in packaged and n not in ALLOWED]
            self.assertFalse(outside, "%s needs %s from the system" % (path.name, outside))
            if any(n in packaged for n in needed):
                self.assertTrue(runpath and all(r.startswith("$ORIGIN") for r in runpath), (path.name, runpath))

    def test_every_dependency_resolves_inside_or_to_the_system_set(self):
        for path in self.elves:
            for name, target in ldd(path).items():
                self.assertIsNotNone(target, "%s: %s not found" % (path.name, name))
                inside = Path(os.path.realpath(target)).is_relative_to(self.root)
                self.assertTrue(inside or name in ALLOWED or os.path.basename(target) in ALLOWED,
                                "%s: %s resolves to %s" % (path.name, name, target))
                if name not in ALLOWED:
                    self.assertTrue(inside, "%s: %s from %s, not from the package" % (path.name, name, target))

    def test_symbol_versions_within_manylinux_2_28(self):
        above = []
        newest = {}
        for path in self.elves:
            for (family, version), symbols in required_versions(path).items():
                newest[family] = max(newest.get(family, version), version)
                if version > MANYLINUX_2_28[family]:
                    above.append("%s needs %s_%s (%s)" % (path.name, family, ".".join(map(str, version)),
                                                          ", ".join(sorted(symbols)[:4])))
        print("[policy] newest symbol versions needed: %s" % ", ".join(
            "%s_%s" % (f, ".".join(map(str, v))) for f, v in sorted(newest.items())), flush=True)
        self.assertFalse(above, "above manylinux_2_28:\n" + "\n".join(above))

    def test_module_loads_from_the_unpacked_package_alone(self):
        code = ("import sys; sys.path.insert(0, %r); import _radiosity; "
                "print(_radiosity.__file__); "
                "print('\\n'.join(sorted({l.split()[-1] for l in open('/proc/self/maps') if '.so' in l})))"
                % str(self.root))
        env = {k: v for k, v in os.environ.items() if k not in ("LD_LIBRARY_PATH", "PYTHONPATH")}
        out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True,
                             cwd=self.root).stdout.split()
        self.assertTrue(Path(out[0]).resolve().is_relative_to(self.root), out[0])
        before_python = set(self.python_libraries(env))
        extra = [p for p in out[1:] if p not in before_python]
        allowed = {stem(name) for name in ALLOWED}
        foreign = [p for p in extra if not Path(p).resolve().is_relative_to(self.root) and stem(p) not in allowed]
        self.assertFalse(foreign, "libraries from the machine: %s" % foreign)
        print("[package] importing _radiosity maps %d shared objects beyond Python's own: %s"
              % (len(extra), ", ".join(os.path.basename(p) for p in extra)), flush=True)

    @staticmethod
    def python_libraries(env):
        code = "print('\\n'.join(sorted({l.split()[-1] for l in open('/proc/self/maps') if '.so' in l})))"
        return subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env,
                              check=True).stdout.split()

    def test_versions_agree(self):
        manifest = tomllib.loads((self.root / "blender_manifest.toml").read_text())
        init = (self.root / "__init__.py").read_text()
        bl_info = re.search(r'"version":\s*\((\d+),\s*(\d+),\s*(\d+)\)', init).groups()
        self.assertEqual(manifest["version"], ".".join(bl_info))
        self.assertEqual(manifest["version"], _radiosity.__version__)


if __name__ == "__main__":
    unittest.main()
