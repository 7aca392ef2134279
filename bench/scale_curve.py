#!/usr/bin/env python3
"""How time, links and memory grow with the scene (issue 32): two families of
generated scenes, solved at quality 0 with sampled visibility, each point in a
process of its own (so the peak resident memory is that solve's own):

- many small objects: a 20 m room with a grid of open boxes (box_field);
- a few dense ones: the same room with four lumpy spheres, each an icosphere
  subdivided to about a quarter of the faces (large_scenes.dense_objects).

    /usr/bin/python3 bench/scale_curve.py [--build build] [--faces 1000 3000 ...]
                                          [--family boxes dense]

Writes <build>/bench/scale_curve.csv and .md, and scale_curve.png: seconds,
links per face and the resident memory the solve adds per face, against
faces, log-log (written again after each point).
One run, one repeat per point: read the slopes, not the last digit (the
machine is shared).
"""

import argparse
import json
import pathlib
import subprocess
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "native"))
sys.path.insert(0, str(ROOT / "bench"))

FAMILIES = {"boxes": "many small objects (open boxes)", "dense": "four dense lumpy spheres"}
DEFAULT_FACES = (1000, 3000, 10000, 30000, 100000)


def scene_of(family, faces):
    """The SceneBuilder of `family` at about `faces` faces."""
    if family == "boxes":
        from synthetic_scenes import box_field
        return box_field(faces)
    from large_scenes import dense_objects
    return dense_objects(faces)


def resident_peak():
    """This process's peak resident bytes since it began (VmHWM: unlike getrusage's
    ru_maxrss, not carried over from the parent through exec)."""
    for line in pathlib.Path("/proc/self/status").read_text().splitlines():
        if line.startswith("VmHWM:"):
            return int(line.split()[1]) * 1024
    raise RuntimeError("no VmHWM in /proc/self/status (Linux only)")


def measure_point(build, family, faces):
    """One solve (this process's whole life): the numbers of one point."""
    sys.path.insert(0, str(ROOT / build / "addon" / "radiosity"))
    import _radiosity as rad
    builder = scene_of(family, faces)
    before = resident_peak()  # the interpreter, numpy and the scene's arrays
    start, start_cpu = time.perf_counter(), time.process_time()
    scene = builder.scene(rad)
    scene_seconds = time.perf_counter() - start
    result = rad.solve(scene, oracle="standard", quality=0.0, visibility="sampled")
    seconds, cpu = time.perf_counter() - start, time.process_time() - start_cpu
    s = result.stats
    n = builder.face_count
    peak = resident_peak()
    return dict(family=family, faces=n, seconds=round(seconds, 2), cpu_seconds=round(cpu, 2),
                scene_seconds=round(scene_seconds, 2), clustering_s=round(s["seconds_clustering"], 2),
                linking_s=round(s["seconds_linking"], 2), elements=s["elements"], links=s["links"],
                cluster_links=s["cluster_links"],
                links_per_face=round((s["links"] + s["cluster_links"]) / n, 1),
                solver_mb=round(s["peak_bytes"] / 2**20, 1), rss_mb=round(peak / 2**20, 1),
                solve_rss_mb=round((peak - before) / 2**20, 1),
                solve_bytes_per_face=round((peak - before) / n), complete=not s["cancelled"])


def plot(rows, path):
    """Three log-log panels, one line per family."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    panels = (("seconds", "seconds (wall)"), ("links_per_face", "links per face (element + cluster)"),
              ("solve_bytes_per_face", "resident bytes the solve adds, per face"))
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    axes[1].set_ylim(10, 200)
    for ax, (key, label) in zip(axes, panels):
        for family, name in FAMILIES.items():
            points = sorted((r["faces"], r[key]) for r in rows if r["family"] == family)
            if points:
                ax.plot(*zip(*points), "o-", label=name)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("input faces")
        ax.set_ylabel(label)
        ax.grid(True, which="both", alpha=0.3)
    # Issue 32's targets: 100,000 faces in 60 s, a million in 15 minutes; 20 links per face.
    axes[0].plot([1e5, 1e6], [60, 900], "k*", markersize=10, label="issue 32's targets")
    axes[1].axhline(20, color="k", linestyle="--", label="issue 32's target")
    axes[1].legend()
    axes[0].legend()
    fig.suptitle("Scale: quality 0, sampled visibility, standard oracle (bench/scale_curve.py)")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--faces", type=int, nargs="+", default=list(DEFAULT_FACES))
    parser.add_argument("--family", nargs="+", choices=sorted(FAMILIES), default=sorted(FAMILIES))
    parser.add_argument("--point", nargs=2, metavar=("FAMILY", "FACES"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.point:
        print(json.dumps(measure_point(args.build, args.point[0], int(args.point[1]))))
        return
    from solver_bench import write_results  # the same CSV and Markdown writer
    out = ROOT / args.build / "bench"
    rows = []
    for family in args.family:
        # The dense family steps by subdivisions (4 x the faces): sizes that round alike run once.
        sizes = {scene_of(family, faces).face_count: faces for faces in sorted(args.faces, reverse=True)}
        for faces in sorted(sizes.values()):
            done = subprocess.run([sys.executable, __file__, "--build", args.build, "--point", family, str(faces)],
                                  check=True, capture_output=True, text=True)
            rows.append(json.loads(done.stdout.strip().splitlines()[-1]))
            print(rows[-1], flush=True)
            write_results(rows, out, "scale_curve")
            plot(rows, out / "scale_curve.png")


if __name__ == "__main__":
    main()
