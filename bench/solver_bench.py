#!/usr/bin/env python3
"""Solver benchmark: elements, links, time and memory per oracle and quality on
array-built scenes, and initial linking on a generated many-face scene.

    /usr/bin/python3 bench/solver_bench.py [--build build] [--faces 10000] [--quick]

Writes a table to stdout and CSV to <build>/bench/solver.csv. Times are the
median of --repeats runs (the machine is shared and noisy).
"""

import argparse
import csv
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "native"))
from synthetic_scenes import SceneBuilder, room_with_blocker  # noqa: E402


def office(b=None):
    """A 5 x 4 x 3 m office: ceiling light, table with legs, a cabinet."""
    b = b or SceneBuilder()
    b.box((0, 0, 0), (5, 4, 3), rho=0.6, inward=True)
    b.polygon([(2.0, 1.5, 2.99), (2.0, 2.5, 2.99), (3.0, 2.5, 2.99), (3.0, 1.5, 2.99)],
              rho=0.0, emission=8.0, two_sided=False)
    b.box((1.8, 1.4, 0.72), (3.2, 2.6, 0.76), rho=(0.5, 0.35, 0.2))  # table top
    for x, y in ((1.85, 1.45), (3.1, 1.45), (1.85, 2.5), (3.1, 2.5)):
        b.box((x, y, 0.0), (x + 0.05, y + 0.05, 0.72), rho=0.3)
    b.box((0.2, 3.3, 0.0), (1.4, 3.9, 1.8), rho=(0.7, 0.7, 0.75))  # cabinet
    return b


def box_field(faces):
    """A room with a light and a grid of open boxes (5 faces each) on the floor."""
    b = SceneBuilder()
    b.box((0, 0, 0), (20, 20, 4), rho=0.6, inward=True)
    b.polygon([(9, 9, 3.99), (9, 11, 3.99), (11, 11, 3.99), (11, 9, 3.99)], rho=0.0, emission=10.0,
              two_sided=False)
    count = max(1, (faces - 7) // 5)
    side = int(np.ceil(np.sqrt(count)))
    pitch = 18.0 / side
    made = 0
    for i in range(side):
        for j in range(side):
            if made < count:
                x, y = 1 + i * pitch, 1 + j * pitch
                # The bottom touches the floor and is never seen: left out.
                b.box((x, y, 0), (x + 0.5 * pitch, y + 0.5 * pitch, 0.5 * pitch), rho=0.5, skip=(0,))
                made += 1
    return b


def measure(rad, builder, oracle, quality, repeats, **options):
    times, result = [], None
    for _ in range(repeats):
        start = time.perf_counter()
        result = rad.solve(builder.scene(rad), oracle=oracle, quality=quality, **options)
        times.append(time.perf_counter() - start)
    s = result.stats
    return dict(oracle=oracle, quality=quality, seconds=statistics.median(times), elements=s["elements"],
                links=s["links"], iterations=s["iterations"], passes=s["passes"],
                bytes_per_element=round(s["bytes_per_element"], 1), bytes_per_link=round(s["bytes_per_link"], 1),
                peak_mb=round(s["peak_bytes"] / 2**20, 1), rss_mb=round(s["peak_rss_bytes"] / 2**20, 1),
                linking_s=round(s["seconds_linking"], 3), cpu_visibility=round(s["cpu_visibility"], 2),
                cpu_form_factors=round(s["cpu_form_factors"], 2), gather_s=round(s["seconds_gather"], 2))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--faces", type=int, default=1000,
                        help="faces of the generated scene (initial linking grows as faces^2.2)")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="fewer points, smaller generated scene")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / args.build / "addon" / "radiosity"))
    import _radiosity as rad

    rows = []
    scenes = {"room": room_with_blocker()[0], "office": office()}
    qualities = (0.3,) if args.quick else (0.3, 0.5)
    for name, builder in scenes.items():
        for oracle in ("standard", "perceptual", "gradient"):
            for quality in qualities:
                row = dict(scene=name, faces=len(builder.faces), **measure(rad, builder, oracle, quality, args.repeats))
                rows.append(row)
                print(row, flush=True)
    faces = 1000 if args.quick else args.faces
    field = box_field(faces)
    row = dict(scene=f"box_field_{len(field.faces)}", faces=len(field.faces),
               **measure(rad, field, "standard", 0.0, 1))
    rows.append(row)
    print(row, flush=True)

    out = ROOT / args.build / "bench"
    out.mkdir(parents=True, exist_ok=True)
    with open(out / "solver.csv", "w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        writer.writeheader()
        writer.writerows(rows)
    print(f"wrote {out / 'solver.csv'}")


if __name__ == "__main__":
    main()
