#!/usr/bin/env python3
"""`make package`: the installable zip of the assembled add-on (BUILD/addon/radiosity),
one per platform: linux-x64 always, windows-x64, macos-arm64 and macos-x64 when their
modules are built (tools/cross_build.py: `make package` builds them where their
dependencies exist, `make test-platforms` first makes those).

    python3 tools/package.py --build build [--require-all]

BUILD/radiosity-VERSION-PLATFORM.zip (a zip name has _ for -) holds one folder,
radiosity/, with the add-on's Python files (bl_info in __init__.py), the platform's
compiled modules, one per CPython version side by side (Python imports the one whose
suffix is its own), and blender_manifest.toml, whose `platforms` lists PLATFORM
alone. So the one zip installs in every Blender:
- 4.2 and later, as an extension (Preferences > Get Extensions > Install from Disk,
  or `blender --command extension install-file`): the installer takes a manifest
  in the zip's one top-level folder as it takes one at the top
  (bl_pkg's pkg_zipfile_detect_subdir_or_none);
- 3.x to 4.1, as an add-on (Preferences > Add-ons > Install): the folder with its
  __init__.py is the add-on, the manifest a file it ignores. A zip with the files
  at its top (as `extension build` lays them out) dropped them loose into
  scripts/addons/ there.
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


# The folder that holds the package inside the zip: the add-on's module name in 3.x.
FOLDER = "radiosity/"


def zip_name(manifest, platform):
    """radiosity-0.1.0-windows_x64.zip."""
    return "%s-%s-%s.zip" % (manifest["id"], manifest["version"], platform.replace("-", "_"))


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
    """{platform: zip} of every platform whose modules are built."""
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
        target = folder.parent.parent / zip_name(manifest, platform)
        made[platform] = write_zip(target, [(source, FOLDER + name) for source, name in entries])
        # Earlier builds' second zip, the add-on alone for 3.x, would mislead.
        (target.parent / zip_name(manifest, "legacy_" + platform)).unlink(missing_ok=True)
    return made


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("--require-all", action="store_true",
                        help="fail unless every platform's modules are built")
    args = parser.parse_args()
    for path in build_packages(args.build, args.require_all).values():
        print("%s (%.1f MB)" % (path, path.stat().st_size / 1e6))
    return 0


if __name__ == "__main__":
    sys.exit(main())
