#!/usr/bin/env python3
"""`make package`: the two installable zips of the assembled add-on (BUILD/addon/radiosity).

    python3 tools/package.py --build build

- BUILD/radiosity-VERSION-linux_x64.zip, the Blender 4.2+ extension: the package's
  files at the top of the zip with blender_manifest.toml, as Blender's own
  `extension build` lays it out; installed from Preferences > Get Extensions >
  Install from Disk, or `blender --command extension install-file`.
- BUILD/radiosity-VERSION-legacy_linux_x64.zip, the add-on for Blender 3.x to 4.1:
  the folder radiosity/ (bl_info in __init__.py), without the manifest; installed
  from Preferences > Add-ons > Install.

Both carry the compiled module with the libraries it needs in radiosity/libs
(cmake/BundleLibraries.cmake), so they need nothing from the system but glibc,
libstdc++ and libgcc_s. Prints the two paths.
"""

import argparse
import sys
import tomllib
import zipfile
from pathlib import Path

MANIFEST = "blender_manifest.toml"
SKIPPED = {"__pycache__"}


def package_files(folder):
    """(path, name inside the package) of every file to ship, in a fixed order."""
    for path in sorted(folder.rglob("*")):
        rel = path.relative_to(folder)
        if path.is_file() and not SKIPPED & set(rel.parts) and path.suffix != ".pyc":
            yield path, rel.as_posix()


def write_zip(target, entries):
    target.unlink(missing_ok=True)
    with zipfile.ZipFile(target, "w", zipfile.ZIP_DEFLATED) as zf:
        for path, name in entries:
            zf.write(path, name)
    return target


def build_packages(build):
    folder = Path(build).resolve() / "addon" / "radiosity"
    if not (folder / MANIFEST).exists() or not list(folder.glob("_radiosity*.so")):
        raise SystemExit("error: no assembled add-on with its module in %s: run `make build` first" % folder)
    manifest = tomllib.loads((folder / MANIFEST).read_text())
    stem = "%s-%s" % (manifest["id"], manifest["version"])
    platform = "_".join(manifest["platforms"]).replace("-", "_")
    files = list(package_files(folder))
    extension = write_zip(folder.parent.parent / ("%s-%s.zip" % (stem, platform)), files)
    legacy = write_zip(folder.parent.parent / ("%s-legacy_%s.zip" % (stem, platform)),
                       [(p, "radiosity/" + n) for p, n in files if n != MANIFEST])
    return extension, legacy


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build", help="build directory")
    args = parser.parse_args()
    for path in build_packages(args.build):
        print("%s (%.1f MB)" % (path, path.stat().st_size / 1e6))
    return 0


if __name__ == "__main__":
    sys.exit(main())
