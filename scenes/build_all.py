#!/usr/bin/env python3
"""Builds every bundled scene (and the contact scenes) into BUILD/scenes/NAME.blend, one Blender process each.

    /usr/bin/python3 scenes/build_all.py --build build --blender blender [NAME ...]
"""

import argparse
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from catalog import CONTACT_SCENES, LIGHT_SCENES, SCENES, TESSELLATED_SCENES  # noqa: E402

ALL = {**SCENES, **CONTACT_SCENES, **LIGHT_SCENES, **TESSELLATED_SCENES}


def build_scene(blender, name, out):
    """Run build_scene.py in a fresh Blender; return (ok, Blender's output)."""
    cmd = [blender, "--background", "--factory-startup", "--python-exit-code", "1",
           "--python", str(HERE / "build_scene.py"), "--", name, str(out)]
    proc = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    return proc.returncode == 0 and out.exists(), proc.stdout + proc.stderr


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("--blender", default="blender", help="Blender executable")
    parser.add_argument("names", nargs="*", metavar="NAME",
                        help="scenes to build (default: all of %s)" % ", ".join(ALL))
    args = parser.parse_args()
    unknown = [n for n in args.names if n not in ALL]
    if unknown:
        parser.error("unknown scene(s) %s; known: %s" % (", ".join(unknown), ", ".join(ALL)))

    out_dir = Path(args.build) / "scenes"
    out_dir.mkdir(parents=True, exist_ok=True)
    failed = 0
    for name in args.names or ALL:
        out = out_dir / ("%s.blend" % name)
        out.unlink(missing_ok=True)
        start = time.perf_counter()
        ok, log = build_scene(args.blender, name, out)
        if ok:
            print("%-15s %s (%.1f s)" % (name, out, time.perf_counter() - start))
        else:
            failed += 1
            print("%-15s FAILED\n%s" % (name, log), file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
