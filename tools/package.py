#!/usr/bin/env python3
"""`make package`: the installable zips of the assembled add-on (BUILD/addon/radiosity),
two per platform: linux-x64 always, windows-x64, macos-arm64 and macos-x64 when their
modules are built (tools/cross_build.py: `make package` builds them where their
dependencies exist, `make test-platforms` first makes those).

    python3 tools/package.py --build build [--require-all]

For each PLATFORM (Blender's names; a zip name has _ for -):
- BUILD/radiosity-VERSION-PLATFORM.zip, the Blender 4.2+ extension: the package's
  files at the top of the zip with blender_manifest.toml, whose `platforms` lists
  PLATFORM alone, as Blender's own `extension build --split-platforms` lays it out;
  installed from Preferences > Get Extensions > Install from Disk, or
  `blender --command extension install-file`.
- BUILD/radiosity-VERSION-legacy_PLATFORM.zip, the add-on for Blender 3.x to 4.1:
  the folder radiosity/ (bl_info in __init__.py), without the manifest; installed
  from Preferences > Add-ons > Install.

Each holds the add-on's Python files and the platform's compiled modules, one per
CPython version side by side (Python imports the one whose suffix is its own).
Prints the paths.
"""

import argparse
import re
import sys
import tomllib
import zipfile
from pathlib import Path

import cross_build  # tools/cross_build.py: the Windows and macOS modules

MANIFEST = "blender_manifest.toml"
SKIPPED = {"__pycache__"}
PLATFORMS = ("linux-x64", *cross_build.PLATFORMS)
# The files of a platform's build: a compiled module, or (a PORTABLE=OFF build) its libraries.
BINARY = re.compile(r"^(_radiosity\..*\.(so|pyd)|libs/.*)$")


def package_files(folder):
    """(path, name inside the package) of every file to ship, in a fixed order."""
    for path in sorted(folder.rglob("*")):
        rel = path.relative_to(folder)
        if path.is_file() and not SKIPPED & set(rel.parts) and path.suffix != ".pyc":
            yield path, rel.as_posix()


def zip_name(manifest, platform, kind):
    """radiosity-0.1.0-windows_x64.zip (kind "extension") or radiosity-0.1.0-legacy_windows_x64.zip."""
    return "%s-%s-%s%s.zip" % (manifest["id"], manifest["version"], "legacy_" if kind == "legacy" else "",
                               platform.replace("-", "_"))


def platform_manifest(text, platform):
    """The manifest's text with `platforms` listing `platform` alone."""
    new, count = re.subn(r'(?m)^platforms\s*=.*$', 'platforms = ["%s"]' % platform, text)
    if count != 1:
        raise SystemExit("error: %s has no single `platforms = [...]` line" % MANIFEST)
    return new


def write_zip(target, entries):
    """entries: (path or bytes, name inside the zip)."""
    target.unlink(missing_ok=True)
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        for source, name in entries:
            if isinstance(source, bytes):
                zf.writestr(name, source)
            else:
                zf.write(source, name)
    return target


def platform_entries(build, folder, platform):
    """(path or bytes, name) of the files of `platform`'s package; None if its modules are missing."""
    common = [(p, n) for p, n in package_files(folder) if not BINARY.match(n) and n != MANIFEST]
    if platform == "linux-x64":
        binaries = [(p, n) for p, n in package_files(folder) if BINARY.match(n) and not n.endswith(".pyd")]
    else:
        found = cross_build.modules(build, platform)
        if len(found) < len(cross_build.cpython.VERSIONS):
            return None
        binaries = [(path, path.name) for path in found.values()]
    manifest = platform_manifest((folder / MANIFEST).read_text(), platform).encode()
    return sorted(common + binaries, key=lambda entry: entry[1]) + [(manifest, MANIFEST)]


def build_packages(build, require_all=False):
    """{platform: (extension zip, legacy zip)} of every platform whose modules are built."""
    folder = Path(build).resolve() / "addon" / "radiosity"
    if not (folder / MANIFEST).exists() or not list(folder.glob("_radiosity*.so")):
        raise SystemExit("error: no assembled add-on with its module in %s: run `make build` first" % folder)
    manifest = tomllib.loads((folder / MANIFEST).read_text())
    made = {}
    for platform in PLATFORMS:
        entries = platform_entries(build, folder, platform)
        if entries is None:
            if require_all:
                raise SystemExit("error: the %s modules are not built: run `make test-platforms` "
                                 "(tools/cross_build.py)" % platform)
            print("%s: not packaged (its modules are not built: `make test-platforms`)" % platform)
            continue
        out = folder.parent.parent
        extension = write_zip(out / zip_name(manifest, platform, "extension"), entries)
        legacy = write_zip(out / zip_name(manifest, platform, "legacy"),
                           [(s, "radiosity/" + n) for s, n in entries if n != MANIFEST])
        made[platform] = (extension, legacy)
    return made


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("--require-all", action="store_true",
                        help="fail unless every platform's modules are built")
    args = parser.parse_args()
    for zips in build_packages(args.build, args.require_all).values():
        for path in zips:
            print("%s (%.1f MB)" % (path, path.stat().st_size / 1e6))
    return 0


if __name__ == "__main__":
    sys.exit(main())
