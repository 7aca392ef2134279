"""report.md of the study: what was run, the references and their noise, the
elements and time each oracle needs at equal error (interpolated along its
curve, curves.py) with each oracle's ratio to the standard oracle's, the
least-squares table of Section 7.3.4, and the Cycles bake comparison. Every table states the signed
exposure error against the path-traced reference (mean linear luminance,
emitter pixels left out) beside the error metrics, which do not see it: the
DoG filter removes brightness, RMS on display brightness dilutes it. Numbers
only come from the rows measured in this run."""

import datetime
import math
import os
import platform

import numpy as np

import curves
import study_config
from study_plots import METRICS


def fmt(v, digits=3):
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    if isinstance(v, (int, np.integer)):
        return str(int(v))
    if abs(v) >= 1000:
        return "%.0f" % v
    return "%.*g" % (digits, v)


def bounded(pair):
    bound, value = pair
    if value is None:
        return "-"
    return fmt(value) if bound == "=" else "%s %s" % (bound, fmt(value))


def pct(v):
    """A signed exposure error as per cent."""
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return "%+.1f %%" % (100 * v)


def exposure_range(rows):
    """'min .. max' of the rows' exposure errors."""
    values = [r["exposure_cycles"] for r in rows]
    return "%s .. %s" % (pct(min(values)), pct(max(values))) if values else "-"


def ratio(a, b):
    return None if a is None or b is None or b == 0 else a / b


def oracle_curves(st, metric, cost):
    out = {}
    for oracle in study_config.ORACLES:
        rows = [r for r in st.rows if r["method"] == "radiosity" and r["oracle"] == oracle]
        out[oracle] = (np.array([r[cost] for r in rows], dtype=float), np.array([r[metric] for r in rows]))
    return out


def equal_error_table(studies, metric):
    """Per scene and error level (three inside the overlap of the standard
    oracle's curve and each other oracle's): each oracle's leaves and seconds to
    reach it, each other oracle's ratio to the standard oracle's (where both are
    interpolated, not bounds), and each oracle's exposure error
    there (interpolated along its curve at the leaves it needs: the solutions
    compared are equally good by `metric`, not necessarily equally bright).
    Returns the table's lines and, per scene, one {oracle: (leaves ratio, time
    ratio)} per level."""
    oracles = study_config.ORACLES
    others = [o for o in oracles if o != "standard"]
    short = study_config.SHORT_NAMES
    head = (["scene", "error"] + ["%s leaves" % short[o] for o in oracles]
            + ["%s/std leaves" % short[o] for o in others] + ["%s s" % short[o] for o in oracles]
            + ["%s/std time" % short[o] for o in others] + ["%s exposure" % short[o] for o in oracles])
    lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    summary = {}
    for st in studies:
        by_leaves = oracle_curves(st, metric, "leaves")
        by_time = oracle_curves(st, metric, "seconds")
        exposure = oracle_curves(st, "exposure_cycles", "leaves")
        # Each oracle against the standard oracle where their two curves overlap
        # (an oracle whose coarsest solution is finer than another's finest
        # still meets the standard oracle's curve).
        levels = sorted({lv for o in others
                         for lv in curves.common_levels([by_leaves["standard"], by_leaves[o]])}, reverse=True)
        if not levels:
            lines.append("| %s | curves do not overlap |%s" % (st.name, " |" * (len(head) - 2)))
            continue
        for level in levels:
            nb = {o: curves.cost_to_reach(*by_leaves[o], level) for o in oracles}
            tb = {o: curves.cost_to_reach(*by_time[o], level) for o in oracles}
            # Ratios only where both costs are interpolated, not bounds.
            n = {o: v for o, (bound, v) in nb.items() if bound == "="}
            t = {o: v for o, (bound, v) in tb.items() if bound == "="}
            ex = {o: curves.value_at_cost(*exposure[o], nb[o][1]) for o in oracles}
            ratios = {o: (ratio(n.get(o), n.get("standard")), ratio(t.get(o), t.get("standard"))) for o in others}
            summary.setdefault(st.name, []).append(ratios)
            cells = ([st.name, fmt(level)] + [bounded(nb[o]) for o in oracles]
                     + ["**%s**" % fmt(ratios[o][0]) for o in others] + [bounded(tb[o]) for o in oracles]
                     + ["**%s**" % fmt(ratios[o][1]) for o in others] + [pct(ex[o]) for o in oracles])
            lines.append("| " + " | ".join(cells) + " |")
    return lines, summary


def targets_table(studies, summaries):
    """Per scene, study_config.TARGET_ORACLE against study_config.TARGETS: the
    median and worst leaves and time ratios to the standard oracle at equal DoG
    error (refined reference; the path trace's medians beside them), the levels
    where even its coarsest solve has more leaves than the standard oracle needs
    (no ratio there, but more leaves all the same), its cost per element over
    the standard oracle's, its exposure range, and which targets it misses."""
    oracle, t = study_config.TARGET_ORACLE, study_config.TARGETS
    lines = ["| scene | leaves ratio median (worst) | time ratio median (worst) | vs Cycles: leaves, time "
             "| levels its coarsest solve is larger | b ratio | exposure | not met |",
             "|---|---|---|---|---|---|---|---|"]
    for st in studies:
        def ratios(metric, k):
            return [lv[oracle][k] for lv in summaries[metric].get(st.name, []) if lv[oracle][k] is not None]
        leaves, time = ratios("dog_refined", 0), ratios("dog_refined", 1)
        median = lambda v: float(np.median(v)) if v else None
        by_leaves = oracle_curves(st, "dog_refined", "leaves")
        # The levels of the equal-error table (every oracle's overlap with the standard's).
        levels = sorted({lv for o in study_config.ORACLES if o != "standard"
                         for lv in curves.common_levels([by_leaves["standard"], by_leaves[o]])})
        larger = 0
        for level in levels:
            own, std = curves.cost_to_reach(*by_leaves[oracle], level), curves.cost_to_reach(*by_leaves["standard"], level)
            larger += own[0] == "<=" and std[0] == "=" and own[1] > std[1]
        fits = {o: curves.least_squares(*[[r[k] for r in st.rows if r["method"] == "radiosity" and r["oracle"] == o]
                                           for k in ("leaves", "seconds")]) for o in ("standard", oracle)}
        b_ratio = ratio(fits[oracle][1], fits["standard"][1])
        rows = [r for r in st.rows if r["method"] == "radiosity" and r["oracle"] == oracle]
        worst_exposure = max((abs(r["exposure_cycles"]) for r in rows), default=None)
        missed = []
        if median(leaves) is None or median(leaves) > t["leaves_ratio"]:
            missed.append("leaves")
        if median(time) is None or median(time) > t["time_ratio"]:
            missed.append("time")
        if (leaves and max(leaves) > t["worst_leaves_ratio"]) or larger:
            missed.append("more leaves at some level")
        if b_ratio is None or not b_ratio <= t["cost_per_element_ratio"]:
            missed.append("cost per element")
        if worst_exposure is None or worst_exposure > t["exposure"]:
            missed.append("exposure")
        lines.append("| %s | %s (%s) | %s (%s) | %s, %s | %d of %d | %s | %s | %s |" % (
            st.name, fmt(median(leaves)), fmt(max(leaves) if leaves else None), fmt(median(time)),
            fmt(max(time) if time else None), fmt(median(ratios("dog_cycles", 0))),
            fmt(median(ratios("dog_cycles", 1))), larger, len(levels), fmt(b_ratio), exposure_range(rows),
            ", ".join(missed) or "none"))
    return lines


def regression_table(studies):
    lines = ["| scene | oracle | n | a (s) | b (s per element) | r | time at 5000 leaves (s) | exposure errors |",
             "|---|---|---|---|---|---|---|---|"]
    for st in studies:
        for oracle in study_config.ORACLES:
            rows = [r for r in st.rows if r["method"] == "radiosity" and r["oracle"] == oracle]
            a, b, r, n = curves.least_squares([x["leaves"] for x in rows], [x["seconds"] for x in rows])
            lines.append("| %s | %s | %d | %s | %s | %s | %s | %s |" % (
                st.name, oracle, n, fmt(a), fmt(b, 4), fmt(r), fmt(a + 5000 * b), exposure_range(rows)))
    return lines


def bake_tables(studies):
    lines = ["| scene | vertices | samples | bake s | DoG vs refined | RMS vs refined | DoG vs Cycles | RMS vs Cycles "
             "| exposure vs Cycles |",
             "|---|---|---|---|---|---|---|---|---|"]
    for st in studies:
        for b in sorted(st.bake_rows, key=lambda b: (b["vertices"], b["samples"])):
            lines.append("| %s | %d | %d | %s | %s | %s | %s | %s | %s |" % (
                st.name, b["vertices"], b["samples"], fmt(b["seconds"]), fmt(b["dog_refined"]),
                fmt(b["rms_refined"]), fmt(b["dog_cycles"]), fmt(b["rms_cycles"]), pct(b["exposure_cycles"])))
    # For each bake: the time each oracle needs to be at least as good against the
    # Cycles reference (interpolated; "<=" even its cheapest solve is; ">" never).
    lines += ["", "Time each oracle needs to reach each bake's error against the **Cycles** reference "
              "(interpolated along its curve; `<= t`: even its cheapest solve is as good; `> t`: not reached "
              "by its dearest solve):", "",
              "| scene | vertices | samples | metric | bake error | bake s | bake exposure | "
              + " | ".join("%s s" % o for o in study_config.ORACLES) + " | "
              + " | ".join("%s exposure" % o for o in study_config.ORACLES) + " |",
              "|" + "---|" * (7 + 2 * len(study_config.ORACLES))]
    for st in studies:
        exposure = oracle_curves(st, "exposure_cycles", "seconds")
        for metric in ("dog_cycles", "rms_cycles"):
            rad = oracle_curves(st, metric, "seconds")
            for b in sorted(st.bake_rows, key=lambda b: (b["vertices"], b["samples"])):
                reach = [curves.cost_to_reach(*rad[o], b[metric]) for o in study_config.ORACLES]
                cells = [bounded(c) for c in reach]
                # Each oracle's exposure where it reaches the bake's error (its dearest solve if it never does).
                ex = [pct(curves.value_at_cost(*exposure[o], c[1])) for o, c in zip(study_config.ORACLES, reach)]
                lines.append("| %s | %d | %d | %s | %s | %s | %s | %s | %s |" % (
                    st.name, b["vertices"], b["samples"], metric.split("_")[0], fmt(b[metric]), fmt(b["seconds"]),
                    pct(b["exposure_cycles"]), " | ".join(cells), " | ".join(ex)))
    return lines


def write(path, studies, settings, plots, figures, seconds):
    s = settings
    sig = None
    try:
        import _image_metric
        sig = _image_metric.edge_filter_sigmas(s["width"])
    except ImportError:
        pass
    out = ["# Speed-accuracy study (source Chapter 7)", "",
           "Generated by `bench/study.py` (%s mode) on %s, %s, %d CPUs; %s. Total %.0f s, of which solving %.0f s."
           % (s["mode"], datetime.datetime.now().strftime("%Y-%m-%d %H:%M"), platform.node(), os.cpu_count(),
              platform.platform(), seconds["total"], seconds["solving"]), "",
           "## Method", "",
           "- Each scene is solved outside Blender (the add-on's export of the scene, Lambertian materials) with "
           "each oracle over a quality range, %d points per oracle placed by bisection on element count (even in "
           "log leaves; `bench/sweep.py`); converged solves (no fixed bounce count), exact visibility; %s; nothing "
           "else runs while solving." % (s["points"], "time = median of %d runs for solves under %.0f s, else one run"
                                         % (s["repeats"], s["repeat_below"]) if s["repeats"] > 1
                                         else "time of one run"),
           "- Snapshots: Cycles renders of the baked colours (the add-on's result meshes emitting their radiance) "
           "from the scene's camera, %d x %d, %d samples of anti-aliasing with a fixed seed, linear EXR, Standard "
           "view transform." % (s["width"], s["height"], s["render_samples"]),
           "- Error (Section 6.2.3): brightness = Rec. 709 luminance clipped to [0, 1] and sRGB-encoded (the "
           "displayed value); **DoG** = eq. 24 on the centre-surround filtered brightness (difference of "
           "Gaussians, sigma %s px centre and %s px surround, i.e. width/160 and 1.6 times that); **RMS** = eq. "
           "24 on the unfiltered brightness; **exposure** = mean linear luminance against the path-traced "
           "reference, signed (below)." % ((fmt(sig[0]), fmt(sig[1])) if sig else ("?", "?")),
           "- References: (a) a far more refined radiosity solution (standard oracle, as in the source, so any "
           "bias favours the standard oracle); (b) Cycles path tracing of the original scene with Lambertian "
           "materials (32 bounces, no clamping), mean of %d seeds of %d samples."
           % (s["reference_seeds"], s["reference_samples"]),
           "- Cycles bake: the same arrays uniformly subdivided (`bench/uniform_mesh.py`), Combined pass baked "
           "to a point float colour attribute, shown through an Emission shader like the radiosity result; "
           "time = the bake operator.", "",
           "## Scenes and references", "",
           "| scene | quality range | refined reference | its leaves | its time (s) | Cycles ref. noise DoG | "
           "noise RMS | noise exposure | refined vs Cycles DoG | refined vs Cycles RMS | refined exposure error |",
           "|---|---|---|---|---|---|---|---|---|---|---|"]
    for st in studies:
        ref = next(r for r in st.rows if r["method"] == "refined")
        out.append("| %s | %s-%s | %s q=%s | %d | %s | %s | %s | %s | %s | %s | %s |" % (
            st.name, fmt(st.quality_range[0]), fmt(st.quality_range[1]), st.reference[0], fmt(st.reference[1]),
            ref["leaves"], fmt(ref["seconds"]), fmt(st.noise["dog"]), fmt(st.noise["rms"]),
            "%.2f %%" % (100 * st.noise["exposure"]), fmt(st.refined_vs_cycles["dog"]),
            fmt(st.refined_vs_cycles["rms"]), pct(st.refined_vs_cycles["exposure"])))
    out += ["", "The Cycles reference's noise is the error its own noise alone causes (measured from the "
            "difference of its seeds); errors against it below that level are not resolved. 'Refined vs Cycles' "
            "is the floor every radiosity curve meets against the Cycles reference (the solver's remaining bias "
            "plus that noise). **Exposure error**: mean linear luminance (not clipped) of a snapshot over the "
            "path-traced one's, minus 1, the pixels the emitters cover left out (the measure of "
            "tests/blender/test_contact.py); > 0 is too bright. Neither DoG (the centre-surround filter removes "
            "brightness) nor RMS (on clipped, sRGB-encoded brightness) shows it, so every table below states it "
            "beside them: a solution can score well and still be too bright (light leaking past contacts, "
            "issue 12) or too dark (energy lost per bounce in closed rooms).", ""]
    out += ["## Elements and time at equal error", "",
            "For each scene, three error levels inside the overlap of each oracle's curve with the standard "
            "oracle's (the rows of all pairs, finest last); the leaves and seconds each "
            "oracle needs to get at least that good (lower envelope of its curve, log-log interpolation), and "
            "each oracle's exposure error there (interpolated along its solves in log leaves): equal error does "
            "not mean equal brightness. The source claims perceptual/standard of about 0.5 for both; issue 16 asks "
            "the same of noticeable/standard.", ""]
    summaries = {}
    for metric, label in METRICS:
        lines, summary = equal_error_table(studies, metric)
        summaries[metric] = summary
        out += ["### %s" % label, ""] + lines + [""]
    others = [o for o in study_config.ORACLES if o != "standard"]
    short = study_config.SHORT_NAMES
    out += ["### Summary: median ratio to the standard oracle over the levels", "",
            "Leaves and time each oracle needs over the standard oracle's at equal error (below 1: fewer), "
            "with the range of each oracle's exposure errors over its whole sweep.", ""]
    head = ["scene"] + ["%s/std %s %s" % (short[o], m.split("_")[0] + " " + m.split("_")[1], what)
                        for m, _ in METRICS for o in others for what in ("leaves", "time")]
    head += ["%s exposure" % short[o] for o in study_config.ORACLES]
    out += ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for st in studies:
        cells = [st.name]
        for metric, _ in METRICS:
            levels = summaries[metric].get(st.name, [])
            for o in others:
                for k in (0, 1):
                    vals = [lv[o][k] for lv in levels if lv[o][k] is not None]
                    cells.append(fmt(float(np.median(vals))) if vals else "-")
        cells += [exposure_range([r for r in st.rows if r["method"] == "radiosity" and r["oracle"] == o])
                  for o in study_config.ORACLES]
        out.append("| " + " | ".join(cells) + " |")
    t = study_config.TARGETS
    out += ["", "### Targets of %s (issue 16)" % study_config.TARGET_ORACLE, "",
            "At equal DoG error: at most %s of the standard oracle's leaves and %s of its time (median over the "
            "levels), never more leaves at any level, cost per element (b below) at most %s times the standard "
            "oracle's, every solve's exposure within %s of the path trace. 'Levels its coarsest solve is larger' "
            "counts the levels of its overlap with the standard oracle's curve where even its coarsest solve has "
            "more leaves than the standard oracle needs there." % (fmt(t["leaves_ratio"]), fmt(t["time_ratio"]),
                                                                  fmt(t["cost_per_element_ratio"]),
                                                                  pct(t["exposure"]).lstrip("+")), ""]
    out += targets_table(studies, summaries)
    out += ["", "## Time against elements (Section 7.3.4: time = a + b x leaves)", ""] + regression_table(studies)
    out += ["", "## Equal-size comparison (Sections 7.4-7.5.2)", "",
            "| scene | oracle | leaves | DoG vs refined | RMS vs refined | DoG vs Cycles | RMS vs Cycles "
            "| exposure vs Cycles |",
            "|---|---|---|---|---|---|---|---|"]
    for st in studies:
        for oracle, r in st.comparison.items():
            out.append("| %s | %s | %d | %s | %s | %s | %s | %s |" % (
                st.name, oracle, r["leaves"], fmt(r["dog_refined"]), fmt(r["rms_refined"]), fmt(r["dog_cycles"]),
                fmt(r["rms_cycles"]), pct(r["exposure_cycles"])))
    out += ["", "## Cycles bake (what a Blender user would do instead)", ""] + bake_tables(studies)
    out += ["", "## Files", ""] + ["- `%s`" % os.path.basename(str(p)) for p in list(plots) + list(figures)]
    out += ["- `study.csv`: every solve and bake with its errors; images and solutions under `study/<scene>/`", ""]
    path.write_text("\n".join(out))
    return path
