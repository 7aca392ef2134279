#!/usr/bin/env python3
"""Solver benchmark: elements, links, time and memory per oracle at two quality
levels on the bundled scenes (exported from Blender as the add-on does) and on
array-built scenes, and generated many-face scenes (a room of open boxes) at
the coarsest quality, where clustering carries the initial linking.

    /usr/bin/python3 bench/solver_bench.py [--build build] [--blender blender]
                                           [--faces 1000 2500 5000 10000] [--quick]

Writes CSV to <build>/bench/solver.csv and a Markdown table to
<build>/bench/solver.md. Times are the median of --repeats runs (the machine is
shared and noisy); CPU seconds of the process are reported beside them.
`seconds` includes making the Scene (validation, patches and contact
meshing), also reported alone as `scene_seconds`; `first_pass_s` is the time
from the same start to the first complete pass (the solution the add-on shows
first). `--only-generated --faces ...` runs the large-scene curve alone
(written to solver_generated.csv / .md).
"""

import argparse
import csv
import json
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "native"))
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "bench"))
from synthetic_scenes import SceneBuilder, add_box, box_field, room_with_blocker  # noqa: E402

BUNDLED = ("cube", "office", "full_office", "dining_room")


def oracles(rad):
    """Every oracle by the solver's name, in its order (its one table, through DEFAULTS_JSON)."""
    return tuple(json.loads(rad.DEFAULTS_JSON)["oracles"])


class ArrayScene:
    """A scene exported from Blender (bench/blender_export.py), solvable like a SceneBuilder."""

    def __init__(self, path):
        self.path = path
        self.arrays = np.load(path)
        self.face_count = len(self.arrays["face_sizes"])

    def scene(self, rad):
        a = self.arrays
        args = (a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"], a["two_sided"])
        if "occludes" in a:
            return rad.Scene(*args, occludes=a["occludes"])
        return rad.Scene(*args)


def export_bundled(name, build, blender):
    """Build the bundled scene's .blend and export its arrays (cached in <build>/bench/scenes)."""
    from build_all import build_scene
    import blender_jobs
    out = ROOT / build / "bench" / "scenes"
    out.mkdir(parents=True, exist_ok=True)
    arrays = out / (name + ".npz")
    if not arrays.exists():
        blend = out / (name + ".blend")
        ok, text = build_scene(blender, name, blend)
        if not ok:
            raise RuntimeError("building %s failed:\n%s" % (name, text[-3000:]))
        blender_jobs.export(blender, blend, str(ROOT / build / "addon"), arrays)
    return ArrayScene(arrays)


def office(b=None):
    """A 5 x 4 x 3 m office: ceiling light, table with legs, a cabinet."""
    b = b or SceneBuilder()
    add_box(b, (0, 0, 0), (5, 4, 3), reflectance=0.6, inward=True)
    b.polygon([(2.0, 1.5, 2.99), (2.0, 2.5, 2.99), (3.0, 2.5, 2.99), (3.0, 1.5, 2.99)],
              reflectance=0.0, emission=8.0, two_sided=False)
    add_box(b, (1.8, 1.4, 0.72), (3.2, 2.6, 0.76), reflectance=(0.5, 0.35, 0.2))  # table top
    for x, y in ((1.85, 1.45), (3.1, 1.45), (1.85, 2.5), (3.1, 2.5)):
        add_box(b, (x, y, 0.0), (x + 0.05, y + 0.05, 0.72), reflectance=0.3)
    add_box(b, (0.2, 3.3, 0.0), (1.4, 3.9, 1.8), reflectance=(0.7, 0.7, 0.75))  # cabinet
    return b


def measure(rad, builder, oracle, quality, repeats, **options):
    times, cpu, scene_times, first_pass, result = [], [], [], [], None
    for _ in range(repeats):
        start, start_cpu = time.perf_counter(), time.process_time()
        passes = []

        def progress(report):
            # The first complete pass: what the viewport shows first (issue 18).
            if report["phase"] == "pass" and not passes:
                passes.append(time.perf_counter() - start)

        scene = builder.scene(rad)  # validation, patches and contact meshing
        scene_times.append(time.perf_counter() - start)
        result = rad.solve(scene, oracle=oracle, quality=quality, progress=progress, **options)
        times.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        first_pass.append(passes[0] if passes else times[-1])
    s = result.stats
    return dict(oracle=oracle, quality=quality, visibility=options.get("visibility", "exact"),
                seconds=round(statistics.median(times), 3),
                first_pass_s=round(statistics.median(first_pass), 3),
                scene_seconds=round(statistics.median(scene_times), 4), patches=scene.patch_count,
                cpu_seconds=round(statistics.median(cpu), 3), leaves=s["leaves"], elements=s["elements"],
                links=s["links"], cluster_links=s["cluster_links"], iterations=s["iterations"], passes=s["passes"],
                bytes_per_element=round(s["bytes_per_element"], 1), bytes_per_link=round(s["bytes_per_link"], 1),
                peak_mb=round(s["peak_bytes"] / 2**20, 1), rss_mb=round(s["peak_rss_bytes"] / 2**20, 1),
                linking_s=round(s["seconds_linking"], 3), clustering_s=round(s["seconds_clustering"], 3),
                cpu_visibility=round(s["cpu_visibility"], 2),
                cpu_form_factors=round(s["cpu_form_factors"], 2), gather_s=round(s["seconds_gather"], 2),
                samples_occluded=s["samples_occluded"], samples_shared=s["samples_shared"])


# The Markdown table's columns (the CSV has them all).
MARKDOWN_KEYS = ("scene", "faces", "patches", "oracle", "quality", "visibility", "seconds", "first_pass_s",
                 "scene_seconds",
                 "cpu_seconds", "leaves", "elements", "links", "cluster_links", "bytes_per_element",
                 "bytes_per_link", "peak_mb", "rss_mb", "linking_s")


def markdown(rows, keys):
    lines = ["| " + " | ".join(keys) + " |", "|" + "---|" * len(keys)]
    lines += ["| " + " | ".join(str(r[k]) for k in keys) + " |" for r in rows]
    return "\n".join(lines) + "\n"


def write_results(rows, out, stem, markdown_keys=None):
    """`rows` (dicts with the same keys) as <out>/<stem>.csv and a Markdown table
    <out>/<stem>.md of `markdown_keys` (default: every key)."""
    out.mkdir(parents=True, exist_ok=True)
    with open(out / (stem + ".csv"), "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    (out / (stem + ".md")).write_text(markdown(rows, markdown_keys or list(rows[0].keys())))
    print(f"wrote {out / (stem + '.csv')} and {out / (stem + '.md')}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--faces", type=int, nargs="+", default=[1000, 2500, 5000, 10000],
                        help="faces of the generated scenes, solved at quality 0 with sampled visibility "
                             "(the curve of issue 18 went on to 20000 50000 100000: minutes each)")
    parser.add_argument("--only-generated", action="store_true",
                        help="only the generated scenes (the large-scene curve)")
    parser.add_argument("--exact-faces", type=int, default=2500,
                        help="also solve the generated scenes up to this size with exact visibility")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="fewer points, smaller generated scene")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / args.build / "addon" / "radiosity"))
    import _radiosity as rad

    rows = []

    def run(name, builder, oracle, quality, repeats, **options):
        row = dict(scene=name, faces=builder.face_count, **measure(rad, builder, oracle, quality, repeats, **options))
        rows.append(row)
        print(row, flush=True)

    scenes = {} if args.only_generated else {
        name: export_bundled(name, args.build, args.blender) for name in (("cube", "office") if args.quick else BUNDLED)}
    if not args.only_generated:
        scenes.update({"room": room_with_blocker()[0], "office_synthetic": office()})
    qualities = (0.3,) if args.quick else (0.3, 0.5)
    for name, builder in scenes.items():
        for oracle in oracles(rad):
            for quality in qualities:
                run(name, builder, oracle, quality, args.repeats)
    for faces in ([250] if args.quick else args.faces):
        field = box_field(faces)
        run("box_field", field, "standard", 0.0, 1, visibility="sampled")
        if faces <= args.exact_faces:
            run("box_field", field, "standard", 0.0, 1, visibility="exact")

    write_results(rows, ROOT / args.build / "bench", "solver_generated" if args.only_generated else "solver",
                  MARKDOWN_KEYS)


if __name__ == "__main__":
    main()
