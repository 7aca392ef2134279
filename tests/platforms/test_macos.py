"""The macOS zips (arm64 and x86-64; `make test-platforms`: tools/cross_build.py's
modules, tools/package.py). macOS cannot run here: each module is checked as a
Mach-O file with LLVM's tools (llvm-objdump-16, llvm-nm-16) and its signature by
code_signature.py.

- the architecture of its zip (arm64 or x86_64), a dylib (zig's linker makes no
  bundles; Python loads either), not marked NOUNDEFS (its Python symbols are
  undefined until it loads);
- the minimum macOS its LC_BUILD_VERSION names: 11.0;
- PyInit__radiosity the one function of its own it exports: besides it only what
  the linker defines (__mh_dylib_header, ___dso_handle) and libc++'s replaceable
  operator new and delete, which keep default visibility (zig's linker takes no
  export list); other images bind their own (two-level namespaces);
- every symbol it needs from outside either bound to libSystem or libc++ (two-level
  names) or a Python C-API symbol (Py*, _Py*) looked up in the process that loads it
  (-undefined dynamic_lookup, flat lookup: Blender's Python provides them);
- the libraries it loads: /usr/lib/libSystem.B.dylib and /usr/lib/libc++.1.dylib at most;
- an ad hoc code signature (rcodesign's) whose CodeDirectory hashes every page
  of the file before it, checked as the kernel checks it (code_signature.py;
  arm64 Macs run no unsigned code);
- and the solver's C++ unit tests, cross-built for each Mac, link.
"""

import re
import subprocess
import unittest

from packages import BUILD, PackageChecks, UnpackedZip, cross_build

import code_signature  # tests/platforms/code_signature.py

ALLOWED_DYLIBS = {"/usr/lib/libSystem.B.dylib", "/usr/lib/libc++.1.dylib"}
ALLOWED_SOURCES = {"libSystem", "libc++"}
PYTHON_API = re.compile(r"^_{1,2}Py")   # Mach-O names carry a leading underscore: _Py_None, __Py_Dealloc
# What a dylib exports besides PyInit__radiosity: the linker's own symbols, and libc++'s
# operator new[]/delete[] (__Znwm, __Znam, __ZdlPv, __ZdaPv and their aligned forms).
LINKER_EXPORTS = {"__mh_dylib_header", "___dso_handle"}
OPERATORS = re.compile(r"^__Z(nw|na|dl|da)")
MIN_MACOS = "11.0"


def tool(name, *args):
    return subprocess.run(["%s-16" % name, *args], capture_output=True, text=True, check=True).stdout


def load_commands(path):
    return tool("llvm-objdump", "--macho", "--private-headers", str(path))


def undefined_symbols(path):
    """{symbol: where it is bound}: a library's short name, or 'dynamically looked up'."""
    found = {}
    for line in tool("llvm-nm", "-m", "-u", str(path)).splitlines():
        match = re.search(r"\(undefined\)\s+(?:weak\s+)?external\s+(\S+)(?:\s+\((.+)\))?", line)
        if match:
            symbol, source = match.groups()
            found[symbol] = (source or "").replace("from ", "")
    return found


class MacPackageChecks(PackageChecks):
    ARCH = None        # llvm-objdump's name of the CPU type

    def test_modules_are_mach_o_bundles_for_this_architecture_and_macos_11(self):
        for minor, path in self.modules.items():
            with self.subTest(python=minor):
                header = tool("llvm-objdump", "--macho", "--private-header", str(path))
                self.assertRegex(header, r"MH_MAGIC_64\s+%s\s" % self.ARCH)
                self.assertRegex(header, r"\s(BUNDLE|DYLIB)\s")
                # Undefined symbols left to the loader: dyld refuses them in a file marked NOUNDEFS.
                self.assertNotRegex(header, r"\bNOUNDEFS\b")
                commands = load_commands(path)
                build = re.search(r"cmd LC_BUILD_VERSION.*?platform (\S+).*?minos (\S+)", commands, re.DOTALL)
                self.assertTrue(build, "no LC_BUILD_VERSION in %s" % path.name)
                self.assertEqual(build.groups(), ("macos", MIN_MACOS))

    def test_exports_pyinit_and_nothing_of_its_own(self):
        for minor, path in self.modules.items():
            with self.subTest(python=minor):
                exported = tool("llvm-nm", "-g", "--defined-only", "-j", str(path)).split()
                self.assertIn("_PyInit__radiosity", exported)
                others = [s for s in exported if s != "_PyInit__radiosity" and s not in LINKER_EXPORTS
                          and not OPERATORS.match(s)]
                self.assertFalse(others, "exports beyond PyInit__radiosity: %s" % others[:20])

    def test_needs_only_python_libsystem_and_libcxx(self):
        for minor, path in self.modules.items():
            with self.subTest(python=minor):
                dylibs = re.findall(r"cmd LC_(?:LOAD|LOAD_WEAK|REEXPORT)_DYLIB\s+cmdsize \d+\s+name (\S+)",
                                    load_commands(path))
                self.assertTrue(set(dylibs) <= ALLOWED_DYLIBS, dylibs)
                symbols = undefined_symbols(path)
                self.assertTrue(symbols)
                python = sorted(s for s, where in symbols.items() if PYTHON_API.match(s))
                # Bound to no library: looked up in the process (flat) when the module loads.
                looked_up = [s for s, where in symbols.items() if where in ("", "dynamically looked up")]
                self.assertTrue(python, "no Python C-API symbol needed: not a Python module?")
                self.assertEqual(sorted(looked_up), python, "looked up at load time but not Python's")
                bad = {s: where for s, where in symbols.items()
                       if s not in python and where not in ALLOWED_SOURCES}
                self.assertFalse(bad, "symbols from elsewhere: %s" % dict(list(bad.items())[:20]))
                print("[macos] %s (%.1f MB): loads %s; %d Python symbols looked up, %d from %s" % (
                    path.name, path.stat().st_size / 1e6, ", ".join(dylibs), len(python),
                    len(symbols) - len(python), ", ".join(sorted(set(symbols.values()) - {
                        "", "dynamically looked up"}))), flush=True)

    def test_signature_verifies(self):
        for minor, path in self.modules.items():
            with self.subTest(python=minor):
                self.assertIn("LC_CODE_SIGNATURE", load_commands(path))
                self.assertEqual(code_signature.check(path), [])


class MacUnitTests(unittest.TestCase):
    """The solver's C++ unit tests cross-built for each macOS (tools/cross_build.py): they
    cannot run here, but they link: a Mach-O executable of that CPU type and macOS 11.0
    that loads libSystem alone."""

    def test_unit_tests_link_for_each_mac(self):
        for platform, arch in (("macos-arm64", "ARM64"), ("macos-x64", "X86_64")):
            with self.subTest(platform=platform):
                path = cross_build.unit_tests(BUILD, platform)
                self.assertTrue(path.exists(), "%s not built: make test-platforms" % path)
                header = tool("llvm-objdump", "--macho", "--private-header", str(path))
                self.assertRegex(header, r"MH_MAGIC_64\s+%s\s.*\sEXECUTE\s" % arch)
                commands = load_commands(path)
                self.assertRegex(commands, re.compile(r"cmd LC_BUILD_VERSION.*?minos %s\s" % re.escape(MIN_MACOS),
                                                      re.DOTALL))
                dylibs = re.findall(r"cmd LC_LOAD_DYLIB\s+cmdsize \d+\s+name (\S+)", commands)
                self.assertEqual(dylibs, ["/usr/lib/libSystem.B.dylib"])
                print("[macos] %s's unit tests link: %s (%.1f MB)" % (platform, path.name, path.stat().st_size / 1e6),
                      flush=True)


class MacArm64PackageTest(MacPackageChecks, UnpackedZip):
    PLATFORM = "macos-arm64"
    ARCH = "ARM64"


class MacX64PackageTest(MacPackageChecks, UnpackedZip):
    PLATFORM = "macos-x64"
    ARCH = "X86_64"


if __name__ == "__main__":
    unittest.main()
