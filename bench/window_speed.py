"""Whether a solve in a Blender window is as fast as a headless one (runs
inside Blender, needs xvfb-run and xdotool): the add-on's polling, status,
live passes and redraws must not starve the solver.

    blender -b --factory-startup --python bench/window_speed.py -- [--build build] [--quick]

full_office at quality 1, first headless on a worker thread (the pipeline the
window's operator runs), then in a window on a virtual display: the leaves
refined after 2, 4 and 6 s in each, and what Esc keeps when pressed at 1.25
times the time of the headless pass completed after 1 s (the latest whose
next pass comes later still): the window keeps that pass only if it runs at
least 80 % as fast. Prints a markdown table (also written to
<build>/bench/window_speed.md); --quick: one round instead of three. The
figures depend on the machine's load: read them as ratios within one run.
"""

import pathlib
import sys

ROOT = pathlib.Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench"))
import in_blender  # noqa: E402

SCENE, QUALITY, MARKS = "full_office", 1.0, (2.0, 4.0, 6.0)


def main():
    args = in_blender.arguments("window_speed.py", "one round instead of three")
    in_blender.load_addon(args.build)
    import solve_timeline

    rows = ["| round | Esc after s | kept: window | kept: headless | refined after 2/4/6 s: window | headless |",
            "|---|---|---|---|---|---|"]
    for round_ in range(1 if args.quick else 3):
        completed, headless_after = solve_timeline.headless_timeline(
            SCENE, QUALITY, MARKS, stop=lambda done, now: now > MARKS[-1])
        times = sorted(completed.values())
        keepable = [i for i in range(len(times) - 1) if times[i][0] >= 1.0 and times[i][0] / 0.8 < times[i + 1][0]]
        if not keepable:
            rows.append("| %d | - | - | - | - | no pass to keep: %s |" % (round_ + 1, times))
            continue
        esc, headless_kept = times[keepable[-1]][0] / 0.8, times[keepable[-1]][1]
        r = solve_timeline.run_window(SCENE, "cancel_after:%.2f" % esc)
        rows.append("| %d | %.1f | %d | %d | %s | %s |" % (
            round_ + 1, esc, r["elements"], headless_kept,
            "/".join(str(r["leaves_after"].get(str(m), "-")) for m in MARKS),
            "/".join(str(headless_after.get(m, "-")) for m in MARKS)))
        print(rows[-1], flush=True)
    in_blender.write_table(args.build, "window_speed", rows)


if __name__ == "__main__":
    main()
