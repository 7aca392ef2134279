#!/usr/bin/env python3
"""`make bench`: the benchmarks that exist so far, in one run.

    /usr/bin/python3 bench/run_bench.py --build build [--quick]

1. Google Benchmark programs of the native core (kernels, visibility): median
   of repetitions, JSON in <build>/bench/<program>.json.
2. The solver sweep (bench/solver_bench.py): elements, links, time and memory
   per oracle and quality, CSV in <build>/bench/solver.csv.
3. Relighting (bench/relight_bench.py): a solve again after only the
   lighting changed, against the first solve and a solve from nothing;
   <build>/bench/relight.csv.
4. The speed-accuracy study (bench/study.py, the source's Chapter 7): sweeps,
   snapshots, error against a refined solution and a Cycles render, Cycles
   bake comparison; <build>/bench/study.csv, study_*.png and report.md. Quick
   mode: fewer points, smaller images, fewer samples (a few minutes).
5. Finely tessellated objects (bench/tessellated_room.py, in Blender): exact
   and sampled visibility against a path trace; <build>/bench/tessellated_room.md.
   Quick mode: the UV sphere only.
6. A solve in a window against a headless one (bench/window_speed.py, in
   Blender under xvfb-run): what Esc keeps and what each has refined after
   2, 4 and 6 s; <build>/bench/window_speed.md. Quick mode: one round.
7. Scale (bench/scale_curve.py): time, links and memory against faces for
   many small objects and a few dense ones, 1,000 to 100,000 faces (quick:
   to 10,000); <build>/bench/scale_curve.{csv,md,png}. Larger points by hand
   (--faces ... 300000 1000000: minutes each, gigabytes).
"""

import argparse
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parent.parent


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--blender", default="blender", help="Blender for the study's renders and bakes")
    parser.add_argument("--quick", action="store_true", help="fewer repetitions and sweep points")
    args = parser.parse_args()
    out = ROOT / args.build / "bench"
    out.mkdir(parents=True, exist_ok=True)
    repetitions = "3" if args.quick else "9"
    for program in ("kernels_bench", "visibility_bench"):
        exe = ROOT / args.build / "bench" / program
        print(f"== {program}", flush=True)
        subprocess.run([str(exe), f"--benchmark_repetitions={repetitions}", "--benchmark_report_aggregates_only=true",
                        f"--benchmark_out={out / (program + '.json')}", "--benchmark_out_format=json"]
                       + (["--benchmark_min_time=0.05"] if args.quick else []), check=True)
    print("== solver", flush=True)
    command = [sys.executable, str(ROOT / "bench" / "solver_bench.py"), "--build", args.build,
               "--blender", args.blender]
    command += ["--quick", "--repeats", "1"] if args.quick else []
    subprocess.run(command, check=True)
    print("== relighting", flush=True)
    subprocess.run([sys.executable, str(ROOT / "bench" / "relight_bench.py"), "--build", args.build,
                    "--blender", args.blender] + (["--quick"] if args.quick else []), check=True)
    print("== speed-accuracy study", flush=True)
    subprocess.run([sys.executable, str(ROOT / "bench" / "study.py"), "--build", args.build, "--blender",
                    args.blender, "--mode", "quick" if args.quick else "full"], check=True)
    print("== finely tessellated objects", flush=True)
    subprocess.run([args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                    str(ROOT / "bench" / "tessellated_room.py"), "--", "--build", args.build]
                   + (["--quick"] if args.quick else []), check=True)
    print("== a solve in a window", flush=True)
    subprocess.run([args.blender, "-b", "--factory-startup", "--python-exit-code", "1", "--python",
                    str(ROOT / "bench" / "window_speed.py"), "--", "--build", args.build]
                   + (["--quick"] if args.quick else []), check=True)
    print("== scale", flush=True)
    subprocess.run([sys.executable, str(ROOT / "bench" / "scale_curve.py"), "--build", args.build]
                   + (["--faces", "1000", "3000", "10000"] if args.quick else []), check=True)


if __name__ == "__main__":
    main()
