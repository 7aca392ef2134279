"""Quality sweep of one oracle on one scene, with points spread evenly in element count.

The source (Section 7.3.1, eq. 29) found output size s ~ 10 / R_c and stepped
its threshold R_c so that sizes came out evenly spaced instead of crowding at
the coarse end. Our quality maps log-linearly onto each oracle's threshold and
the size still grows steeply and unevenly with it (and, for the perceptual
oracle in furnished rooms, hardly at all at first), so instead of a fitted law
the sweep bisects on element count directly: it solves the two ends of the
quality range, then repeatedly splits the widest gap in log(leaves) between
neighbouring solves, at the quality interpolated (linearly in log leaves) to
land in the gap's middle. Every solve is kept as a data point. The spacing is
even in log(leaves) because the counts span two decades and are plotted on
log axes (on the source's linear axes they would crowd at the origin again).
"""

import math
import statistics
import time

import numpy as np

MIN_QUALITY_STEP = 0.004   # below this, two qualities are the same point


def load_scene(rad, npz_path):
    a = np.load(npz_path)
    return rad.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                     a["two_sided"])


def save_result(result, path):
    np.savez(path, positions=result.positions, face_vertices=result.face_vertices, face_sizes=result.face_sizes,
             radiance=result.radiance, vertex_irradiance=result.vertex_irradiance, source_face=result.source_face,
             source_side=result.source_side)


def solve_point(rad, scene, oracle, quality, repeats=1, repeat_below=0.0):
    """Solve; returns (result, row). The time is the median over `repeats` runs
    if the first run took less than `repeat_below` seconds, else the one run."""
    times = []
    result = None
    while True:
        start = time.perf_counter()
        result = rad.solve(scene, oracle=oracle, quality=quality)
        times.append(time.perf_counter() - start)
        if len(times) >= repeats or times[0] >= repeat_below:
            break
    s = result.stats
    row = dict(oracle=oracle, quality=round(quality, 5), threshold=rad.quality_threshold(oracle, quality),
               leaves=s["leaves"], elements=s["elements"], links=s["links"], vertices=len(result.positions),
               seconds=statistics.median(times), seconds_min=min(times), repeats=len(times),
               iterations=s["iterations"], passes=s["passes"], peak_mb=s["peak_bytes"] / 2**20,
               stopped_by=s["stopped_by"], cpu_visibility=s["cpu_visibility"],
               cpu_form_factors=s["cpu_form_factors"], seconds_linking=s["seconds_linking"])
    return result, row


def next_quality(points):
    """The quality that splits the widest log(leaves) gap between neighbouring
    solves, or None when no gap can be split further. points: [(quality, leaves)]."""
    points = sorted(points)
    best, best_gap = None, 0.0
    for (q0, n0), (q1, n1) in zip(points, points[1:]):
        if q1 - q0 < 2 * MIN_QUALITY_STEP:
            continue
        gap = abs(math.log(n1) - math.log(n0))
        # Equal counts still hide an unknown step somewhere between: worth a
        # look only if nothing better is left (tiny gap value).
        gap = max(gap, 1e-6 * (q1 - q0))
        if gap > best_gap:
            target = 0.5 * (math.log(n0) + math.log(n1))
            t = 0.5 if n1 == n0 else (target - math.log(n0)) / (math.log(n1) - math.log(n0))
            # Keep clear of both ends so that a flat stretch still gets split.
            t = min(max(t, 0.2), 0.8)
            best, best_gap = q0 + t * (q1 - q0), gap
    return best


def sweep(rad, scene, oracle, quality_range, points, on_solve, repeats=1, repeat_below=0.0):
    """Solve `points` qualities in `quality_range`; on_solve(result, row) gets each."""
    lo, hi = quality_range
    done = []
    for q in (lo, hi):
        result, row = solve_point(rad, scene, oracle, q, repeats, repeat_below)
        on_solve(result, row)
        done.append((q, max(1, row["leaves"])))
    while len(done) < points:
        q = next_quality(done)
        if q is None:
            break
        result, row = solve_point(rad, scene, oracle, q, repeats, repeat_below)
        on_solve(result, row)
        done.append((q, max(1, row["leaves"])))


def match_leaves(rad, scene, oracle, target, known, q_max, tries=4, tolerance=0.08):
    """A solve of `oracle` with about `target` leaves (the equal-size comparison of
    Section 7.5.2), by secant steps in (quality, log leaves) from the sweep's
    points `known` [(quality, leaves)], beyond the sweep's top if needed (up to
    q_max). Returns (result, row), the closest found, or None if the target lies
    below the oracle's coarsest solve (the caller then takes that solve)."""
    known = sorted(known)
    best = None
    for _ in range(tries):
        below = [p for p in known if p[1] <= target]
        above = [p for p in known if p[1] > target]
        if not below:
            break
        if above:
            (q0, n0), (q1, n1) = below[-1], above[0]
            lo, hi = q0, q1
        else:   # extrapolate from the two finest solves
            (q0, n0), (q1, n1) = known[-2], known[-1]
            lo, hi = q1, q_max
        if hi - lo < MIN_QUALITY_STEP:
            break
        t = (math.log(target) - math.log(n0)) / (math.log(n1) - math.log(n0)) if n1 != n0 else 1.5
        q = min(max(q0 + t * (q1 - q0), lo + 0.05 * (hi - lo)), hi - 0.05 * (hi - lo))
        result, row = solve_point(rad, scene, oracle, q)
        known = sorted(known + [(q, max(1, row["leaves"]))])
        error = abs(math.log(row["leaves"] / target))
        if best is None or error < abs(math.log(best[1]["leaves"] / target)):
            best = (result, row)
        if error < tolerance:
            break
    return best
