#!/usr/bin/env python3
"""How closely the solver keeps a time budget in wall time, the measurement
behind tests/native/test_robustness.py's Budgets (which read the budget on a
fake clock, so that they do not depend on the machine's load).

    /usr/bin/python3 bench/time_budget.py [--build build] [--repeats 3]

Two cases: a room solved with a million bounces (the gather loop must stop)
and 2,000 boxes linked at quality 1 (linking must stop). For each budget, the
wall seconds solve() took and the overrun past the budget; the contract is
10 % plus one second. Prints a Markdown table. The figures depend on the
machine's load: run it on an idle machine, or beside a load to see its effect.
"""

import argparse
import pathlib
import statistics
import sys
import time

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests" / "native"))
from synthetic_scenes import box_field, room_with_blocker  # noqa: E402

CASES = {
    "room, 10^6 bounces": (lambda: room_with_blocker()[0], dict(bounces=10**6, quality=0.3)),
    "2,000 boxes, linking": (lambda: box_field(2000), dict(quality=1.0)),
}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--budgets", type=float, nargs="+", default=[0.5, 1.0, 2.0])
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / args.build / "addon" / "radiosity"))
    import _radiosity as rad

    print("| case | budget s | wall s (median of %d) | worst overrun s | within 10 %% + 1 s | stopped by |"
          % args.repeats)
    print("|---|---|---|---|---|---|")
    for name, (make, options) in CASES.items():
        scene = make().scene(rad)
        for budget in args.budgets:
            walls, stops = [], set()
            for _ in range(args.repeats):
                start = time.perf_counter()
                result = rad.solve(scene, time_budget=budget, **options)
                walls.append(time.perf_counter() - start)
                stops.add(result.stats["stopped_by"])
            worst = max(walls) - budget
            print("| %s | %.1f | %.2f | %.2f | %s | %s |" % (
                name, budget, statistics.median(walls), worst, "yes" if max(walls) < 1.1 * budget + 1.0 else "NO",
                ", ".join(sorted(stops))))


if __name__ == "__main__":
    main()
