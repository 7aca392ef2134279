#!/usr/bin/env python3
"""The speed-accuracy study of the source's Chapter 7 (issue 7), on the bundled scenes.

    /usr/bin/python3 bench/study.py --build build --blender blender [--mode full|quick|smoke]
                                    [--scenes cube office ...] [--out DIR]

For each scene and oracle: a quality sweep with element counts spread evenly
(sweep.py), solved outside Blender with nothing else running (median time of
repeats); snapshots of every solution from the scene's camera (Cycles, baked
colours only); the error of Section 6.2.3 (eq. 24 on centre-surround filtered
brightness, and plain RMS) against two references: a far more refined
radiosity solution (standard oracle, as in the source) and a path-traced Cycles
render of the original scene (noise measured with two seeds); the Cycles bake a
Blender user would do instead, on uniformly subdivided meshes. Writes, under
<out> (default <build>/bench): study.csv, the plots, the equal-size comparison
figures and report.md; the images and solutions under <out>/study/<scene>.
"""

import argparse
import csv
import json
import math
import pathlib
import sys
import time

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(ROOT / "scenes"))
sys.path.insert(0, str(ROOT / "tests" / "blender"))   # image_agreement (numpy only)

import numpy as np  # noqa: E402

import blender_jobs  # noqa: E402
import image_agreement  # noqa: E402
import study_config  # noqa: E402
import sweep  # noqa: E402
from build_all import build_scene  # noqa: E402

CSV_FIELDS = ("scene", "method", "oracle", "quality", "threshold", "leaves", "elements", "links", "vertices",
              "seconds", "seconds_min", "repeats", "iterations", "passes", "peak_mb", "stopped_by",
              "cpu_visibility", "cpu_form_factors", "seconds_linking", "samples", "matched",
              "dog_refined", "rms_refined", "dog_cycles", "rms_cycles", "exposure_cycles", "image")


def log(message):
    print(message, flush=True)


class SceneStudy:
    """Everything measured on one scene; files under out/study/<name>."""

    def __init__(self, name, out, settings):
        self.name = name
        self.dir = out / "study" / name
        (self.dir / "solutions").mkdir(parents=True, exist_ok=True)
        (self.dir / "images").mkdir(parents=True, exist_ok=True)
        self.settings = settings
        self.quality_range, self.reference = study_config.scene_plan(name, settings)
        self.rows = []            # radiosity and refined rows (dicts)
        self.bake_rows = []
        self.comparison = {}      # oracle -> row of the equal-size comparison
        self.noise = None
        self.blend = self.dir / "scene.blend"
        self.arrays = self.dir / "arrays.npz"
        self.mask_path = self.dir / "images" / "emitter_mask.npy"

    def solution_path(self, tag):
        return self.dir / "solutions" / ("%s.npz" % tag)

    def image_path(self, tag, suffix=".exr"):
        return self.dir / "images" / ("%s%s" % (tag, suffix))


def prepare(study, blender, addon, verbose):
    ok, text = build_scene(blender, study.name, study.blend)
    if not ok:
        raise blender_jobs.BlenderError("building scene %s failed:\n%s" % (study.name, text[-3000:]))
    blender_jobs.export(blender, study.blend, addon, study.arrays, verbose)


def solve_all(rad, study, settings):
    """The sweeps, the refined reference and the equal-size solves (no Blender running)."""
    scene = sweep.load_scene(rad, study.arrays)
    known = {}
    for oracle in study_config.ORACLES:
        count = [0]

        def keep(result, row, oracle=oracle, count=count):
            tag = "%s_%02d" % (oracle, count[0])
            count[0] += 1
            sweep.save_result(result, study.solution_path(tag))
            study.rows.append(dict(row, scene=study.name, method="radiosity", tag=tag, matched=0))
            log("  %-11s %-10s q=%.3f  %6d leaves %8d links %7.2f s" % (study.name, oracle, row["quality"],
                                                                       row["leaves"], row["links"], row["seconds"]))

        sweep.sweep(rad, scene, oracle, study.quality_range, settings["points"], keep,
                    settings["repeats"], settings["repeat_below"])
        known[oracle] = [(r["quality"], max(1, r["leaves"])) for r in study.rows if r["oracle"] == oracle]

    oracle, quality = study.reference
    result, row = sweep.solve_point(rad, scene, oracle, quality)
    sweep.save_result(result, study.solution_path("refined"))
    study.rows.append(dict(row, scene=study.name, method="refined", tag="refined", matched=0))
    log("  %-11s refined reference: %s q=%.3f, %d leaves, %.1f s" % (study.name, oracle, quality, row["leaves"],
                                                                    row["seconds"]))
    match_sizes(rad, scene, study, known)


def match_sizes(rad, scene, study, known):
    """Solutions of every oracle with (about) the same number of leaves, for the
    figures of Sections 7.4-7.5.2: a size inside every oracle's range if there
    is one, low enough that the coarse mesh still shows (a quarter of the way up
    the overlap, in log), else the largest of the oracles' coarsest sizes."""
    ranges = {o: (min(n for _, n in k), max(n for _, n in k)) for o, k in known.items()}
    lo = max(r[0] for r in ranges.values())
    hi = min(r[1] for r in ranges.values())
    # No common range (an oracle's coarsest solve is finer than another's finest):
    # the size of the coarsest solve that every oracle can match by refining further.
    target = (lo ** 0.75 * hi ** 0.25) if lo < hi else lo
    for oracle in study_config.ORACLES:
        rows = [r for r in study.rows if r["oracle"] == oracle and r["method"] == "radiosity"]
        nearest = min(rows, key=lambda r: abs(math.log(max(1, r["leaves"]) / target)))
        if abs(math.log(max(1, nearest["leaves"]) / target)) > 0.08:
            found = sweep.match_leaves(rad, scene, oracle, target, known[oracle], study.reference[1] - 0.01)
            if found is not None and (abs(math.log(found[1]["leaves"] / target))
                                      < abs(math.log(max(1, nearest["leaves"]) / target))):
                result, row = found
                tag = "%s_match" % oracle
                sweep.save_result(result, study.solution_path(tag))
                nearest = dict(row, scene=study.name, method="radiosity", tag=tag, matched=1)
                study.rows.append(nearest)
        study.comparison[oracle] = nearest
    log("  %-11s equal-size comparison at ~%d leaves: %s" % (
        study.name, target, ", ".join("%s %d" % (o, r["leaves"]) for o, r in study.comparison.items())))


def render_all(metric, study, settings, blender, addon, cache_dir, verbose):
    import references
    s = settings
    solutions = []
    comparison_tags = {r["tag"] for r in study.comparison.values()} | {"refined"}
    for row in study.rows:
        job = dict(npz=str(study.solution_path(row["tag"])), exr=str(study.image_path(row["tag"])))
        if row["tag"] in comparison_tags:
            job["edges"] = str(study.image_path(row["tag"] + "_edges", ".npy"))
        solutions.append(job)
    start = time.perf_counter()
    blender_jobs.run_with_jobs(blender, study.blend, "blender_render.py", addon,
                               dict(width=s["width"], height=s["height"], samples=s["render_samples"],
                                    camera=str(study.dir / "camera.json"), mask=str(study.mask_path),
                                    solutions=solutions),
                               study.dir / "render_jobs.json", verbose)
    log("  %-11s rendered %d snapshots (%.0f s)" % (study.name, len(solutions), time.perf_counter() - start))
    start = time.perf_counter()
    _, study.noise = references.cycles_reference(metric, blender, study.blend, addon, study.name, s,
                                                 study.dir / "images", cache_dir, verbose)
    log("  %-11s Cycles reference (%d x %d samples, %.0f s): noise DoG %.2e, RMS %.2e" % (
        study.name, s["reference_seeds"], s["reference_samples"], time.perf_counter() - start,
        study.noise["dog"], study.noise["rms"]))
    start = time.perf_counter()
    bake_out = study.dir / "bake.json"
    blender_jobs.run_with_jobs(blender, study.blend, "blender_bake.py", addon,
                               dict(width=s["width"], height=s["height"], render_samples=s["render_samples"],
                                    pairs=[list(p) for p in s["bake"]], out_dir=str(study.dir / "images"),
                                    results=str(bake_out)),
                               study.dir / "bake_jobs.json", verbose)
    for b in json.loads(bake_out.read_text()):
        study.bake_rows.append(dict(scene=study.name, method="cycles_bake", oracle="", vertices=b["vertices"],
                                    elements=b["polygons"], samples=b["samples"], seconds=b["bake_seconds"],
                                    repeats=1, tag=pathlib.Path(b["exr"]).stem, matched=0))
    log("  %-11s Cycles bakes: %d (%.0f s)" % (study.name, len(study.bake_rows), time.perf_counter() - start))


def exposure(metric, study, exr, reference="cycles"):
    """Signed exposure error of a snapshot against the path-traced reference:
    mean linear luminance over the reference's, minus 1, emitter pixels left out
    (tests/blender/image_agreement.py, the measure of the agreement tests)."""
    return image_agreement.compare(metric.read_image(str(exr)), metric.read_image(str(study.image_path(reference))),
                                   np.load(study.mask_path))["exposure"]


def score_all(metric, study):
    refined = str(study.image_path("refined"))
    cycles = str(study.image_path("cycles"))
    filtered = {r["tag"] for r in study.comparison.values()} | {"refined"}
    for row in study.rows + study.bake_rows:
        exr = str(study.image_path(row["tag"]))
        out = str(study.image_path(row["tag"] + "_dog")) if row["tag"] in filtered else None
        a = metric.image_errors(exr, refined, filtered_output=out)
        b = metric.image_errors(exr, cycles)
        row.update(dog_refined=a["dog"], rms_refined=a["rms"], dog_cycles=b["dog"], rms_cycles=b["rms"],
                   exposure_cycles=exposure(metric, study, exr),
                   image=str(pathlib.Path(exr).relative_to(study.dir.parent.parent)))
    # The reference solution against the path-traced render: the floor of the Cycles curves.
    study.refined_vs_cycles = dict(metric.image_errors(refined, cycles), exposure=exposure(metric, study, refined))
    metric.image_errors(cycles, refined, filtered_output=str(study.image_path("cycles_dog")))
    # The reference's own exposure noise: its seeds differ by sqrt(2) times one
    # render's noise, the mean of k seeds has 1/sqrt(k) of it (as references.py).
    seeds = sorted(study.dir.joinpath("images").glob("cycles_seed*.exr"))
    if len(seeds) >= 2:
        d = exposure(metric, study, seeds[0], reference=seeds[1].stem)
        study.noise["exposure"] = abs(d) / math.sqrt(2.0 * len(seeds))
    else:
        study.noise["exposure"] = float("nan")


def write_csv(path, studies):
    with open(path, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=CSV_FIELDS, extrasaction="ignore")
        w.writeheader()
        for st in studies:
            for row in st.rows + st.bake_rows:
                w.writerow({k: (round(v, 6) if isinstance(v, float) else v) for k, v in row.items()})


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--mode", default="full", choices=sorted(study_config.MODES))
    parser.add_argument("--scenes", nargs="*", help="default: the mode's scenes")
    parser.add_argument("--out", help="output folder (default <build>/bench)")
    parser.add_argument("-v", "--verbose", action="store_true")
    args = parser.parse_args()
    settings = study_config.settings(args.mode)
    build = (ROOT / args.build).resolve() if not pathlib.Path(args.build).is_absolute() else pathlib.Path(args.build)
    addon = str(build / "addon")
    sys.path.insert(0, str(build / "addon" / "radiosity"))
    sys.path.insert(0, str(build / "study"))   # _image_metric, the study-only module
    import _image_metric as metric
    import _radiosity as rad
    out = pathlib.Path(args.out).resolve() if args.out else build / "bench"
    out.mkdir(parents=True, exist_ok=True)
    names = args.scenes or settings["scenes"]
    for n in names:
        if n not in study_config.SCENES:
            parser.error("no study plan for scene %r (known: %s)" % (n, ", ".join(study_config.SCENES)))
    started = time.perf_counter()
    log("== study (%s mode): %s" % (args.mode, ", ".join(names)))
    studies = [SceneStudy(n, out, settings) for n in names]
    for st in studies:
        prepare(st, args.blender, addon, args.verbose)
    log("== solving (nothing else running)")
    for st in studies:
        solve_all(rad, st, settings)
    solve_seconds = time.perf_counter() - started
    log("== rendering, references, Cycles bakes")
    for st in studies:
        render_all(metric, st, settings, args.blender, addon, out / "cache", args.verbose)
        score_all(metric, st)
    write_csv(out / "study.csv", studies)
    import study_figures
    import study_plots
    import study_report
    for stale in out.glob("study_compare_*.png"):   # scenes of an earlier run in another mode
        stale.unlink()
    plots = study_plots.plot_all(studies, out)
    figures = study_figures.comparison_figures(metric, studies, out)
    study_report.write(out / "report.md", studies, settings, plots, figures,
                       dict(total=time.perf_counter() - started, solving=solve_seconds))
    log("== study done in %.0f s: %s, %s, %d plots, %d figures"
        % (time.perf_counter() - started, out / "study.csv", out / "report.md", len(plots), len(figures)))


if __name__ == "__main__":
    main()
