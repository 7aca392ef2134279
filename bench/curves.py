"""The numbers read off the study's curves (no plotting here).

- least_squares: the line y = a + b x and correlation r of Section 7.3.4.
- value_at_cost: another quantity of a method's solves (the exposure error)
  where its curve has a given cost, to state it beside an equal-error cost.
- cost_at_error: how many elements (or seconds) a method needs to reach an
  error level. The measured error does not fall strictly monotonically with
  refinement (a finer mesh can move a shadow edge the wrong way), so the curve
  is first made monotone by keeping, at each cost, the best error reached at
  that cost or less (the lower envelope): "what it takes to get at least this
  good". The cost is then interpolated linearly in log-log between the two
  envelope points around the level.
"""

import math

import numpy as np


def least_squares(x, y):
    """(a, b, r, n) of the best line y = a + b x."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    n = len(x)
    if n < 2 or np.ptp(x) == 0:
        return float("nan"), float("nan"), float("nan"), n
    b, a = np.polyfit(x, y, 1)
    r = float(np.corrcoef(x, y)[0, 1]) if np.ptp(y) > 0 else float("nan")
    return float(a), float(b), r, n


def envelope(cost, error):
    """Points (cost, best error so far) in increasing cost, only where the best improves."""
    order = np.argsort(cost, kind="stable")
    out, best = [], math.inf
    for i in order:
        if error[i] < best:
            best = error[i]
            out.append((float(cost[i]), float(error[i])))
    return out


def cost_at_error(cost, error, level):
    """Interpolated cost at which the envelope first reaches `level`; None if it
    never does, or if the cheapest point is already better (cost unknown below it)."""
    env = envelope(np.asarray(cost, dtype=float), np.asarray(error, dtype=float))
    if not env or env[-1][1] > level or env[0][1] <= level:
        return None
    for (c0, e0), (c1, e1) in zip(env, env[1:]):
        if e1 <= level < e0:
            t = (math.log(level) - math.log(e0)) / (math.log(e1) - math.log(e0))
            return math.exp(math.log(c0) + t * (math.log(c1) - math.log(c0)))
    return None


def cost_to_reach(cost, error, level):
    """(bound, value): ("=", interpolated cost), ("<=", cheapest cost) when even the
    cheapest point is at least as good, or (">", dearest cost) when never reached."""
    env = envelope(np.asarray(cost, dtype=float), np.asarray(error, dtype=float))
    if not env:
        return None, None
    if env[0][1] <= level:
        return "<=", env[0][0]
    value = cost_at_error(cost, error, level)
    return ("=", value) if value is not None else (">", env[-1][0])


def value_at_cost(cost, value, at):
    """`value` of the solves interpolated linearly in log cost at cost `at` (the
    end value outside the solves' range); None without solves or cost."""
    cost, value = np.asarray(cost, dtype=float), np.asarray(value, dtype=float)
    if at is None or len(cost) == 0:
        return None
    order = np.argsort(cost, kind="stable")
    return float(np.interp(math.log(at), np.log(cost[order]), value[order]))


def common_levels(curves, count=3):
    """`count` error levels, geometrically spaced, that every curve (list of
    (cost, error) arrays) passes through: between the largest of the curves'
    best errors and the smallest of their worst errors. Empty if they do not overlap."""
    lo = max(min(e) for _, e in curves)
    hi = min(max(e) for _, e in curves)
    if not lo < hi:
        return []
    # Stay a little inside both ends, where each curve has points on both sides.
    lo, hi = lo * (hi / lo) ** 0.1, hi * (lo / hi) ** 0.1
    return list(np.geomspace(hi, lo, count))
