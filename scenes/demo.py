#!/usr/bin/env python3
"""`make demo`: build a bundled scene, solve it in headless Blender, save and render it.

    /usr/bin/python3 scenes/demo.py --build build --blender blender --scene office

Writes BUILD/demo/SCENE.blend (the solved scene) and BUILD/demo/SCENE.png (a
Cycles render from the scene's camera) and prints where they are. The add-on
is loaded from BUILD/addon, as built by `make`.
"""

import argparse
import json
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

from build_all import build_scene  # noqa: E402
from catalog import SCENES  # noqa: E402

# Lines the Blender side prints for the user; everything else is Blender's log.
TAG = "[demo] "


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build", help="build directory")
    parser.add_argument("--blender", default="blender", help="Blender executable")
    parser.add_argument("--scene", default="office", choices=sorted(SCENES))
    parser.add_argument("--oracle", default="PERCEPTUAL", help="the oracle's setting, as the solver names it in capitals")
    parser.add_argument("--samples", type=int, default=32, help="Cycles samples of the render")
    parser.add_argument("-v", "--verbose", action="store_true", help="show Blender's output")
    args = parser.parse_args()

    build = Path(args.build).resolve()
    addon = build / "addon"
    if not (addon / "radiosity" / "__init__.py").exists():
        sys.exit("error: no add-on in %s; run `make` first" % addon)
    oracles = json.loads((addon / "radiosity" / "solver_defaults.json").read_text())["oracles"]
    if args.oracle.lower() not in oracles:
        parser.error("--oracle must be one of %s" % ", ".join(name.upper() for name in oracles))
    scene_file = build / "scenes" / ("%s.blend" % args.scene)
    out_dir = build / "demo"
    out_dir.mkdir(parents=True, exist_ok=True)
    blend, png = out_dir / ("%s.blend" % args.scene), out_dir / ("%s.png" % args.scene)
    for path in (blend, png):
        path.unlink(missing_ok=True)

    start = time.perf_counter()
    scene_file.parent.mkdir(parents=True, exist_ok=True)
    ok, log = build_scene(args.blender, args.scene, scene_file)
    if not ok:
        sys.exit("error: building scene %r failed:\n%s" % (args.scene, log))
    print("built scene %s (%.1f s)" % (scene_file, time.perf_counter() - start))

    # Factory settings: the user's own preferences and add-ons stay out of the demo.
    cmd = [args.blender, "--background", "--factory-startup", str(scene_file), "--python-exit-code", "1",
           "--python", str(HERE / "demo_blender.py"), "--",
           "--addon", str(addon), "--oracle", args.oracle, "--samples", str(args.samples),
           "--blend", str(blend), "--png", str(png)]
    proc = subprocess.run(cmd, capture_output=True, text=True, stdin=subprocess.DEVNULL)
    log = proc.stdout + proc.stderr
    for line in log.splitlines():
        if args.verbose or line.startswith(TAG):
            print(line[len(TAG):] if line.startswith(TAG) else line)
    if proc.returncode != 0 or not blend.exists() or not png.exists():
        if not args.verbose:
            print(log, file=sys.stderr)
        sys.exit("error: the demo did not complete (Blender exit code %d)" % proc.returncode)
    print("demo done in %.1f s" % (time.perf_counter() - start))
    print("  scene:  %s" % blend)
    print("  render: %s" % png)


if __name__ == "__main__":
    main()
