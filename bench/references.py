"""The path-traced Cycles reference of a scene, and how noisy it is.

It is rendered with `seeds` different seeds; the reference is their mean, and
its noise is measured with the study's own metric: two independent renders
differ by sqrt(2) times one render's noise, their mean carries half the
difference (d / 2). The images depend only on the scene, the render settings
and Blender, not on the solver, so they are cached under <out>/cache, keyed by
the files that make the scene and the settings.
"""

import hashlib
import json
import pathlib
import shutil
import subprocess

import numpy as np

import blender_jobs

ROOT = pathlib.Path(__file__).resolve().parent.parent
KEY_FILES = ("scenes/scene_kit.py", "bench/blender_common.py", "bench/blender_render.py")


def cache_key(blender, scene, width, height, samples, seed):
    h = hashlib.sha256()
    for name in KEY_FILES + ("scenes/%s.py" % scene,):
        h.update((ROOT / name).read_bytes())
    version = subprocess.run([blender, "--version"], capture_output=True, text=True).stdout.splitlines()[:1]
    h.update(json.dumps([version, width, height, samples, seed]).encode())
    return h.hexdigest()[:16]


def cycles_reference(metric, blender, blend, addon, scene, settings, out_dir, cache_dir, verbose=False):
    """Writes out_dir/cycles.exr (mean of the seeds); returns its path and the noise dict."""
    out_dir, cache_dir = pathlib.Path(out_dir), pathlib.Path(cache_dir)
    cache_dir.mkdir(parents=True, exist_ok=True)
    w, h, samples = settings["width"], settings["height"], settings["reference_samples"]
    seeds = list(range(1, settings["reference_seeds"] + 1))
    cached = [cache_dir / ("%s_%s.exr" % (scene, cache_key(blender, scene, w, h, samples, s))) for s in seeds]
    missing = [dict(exr=str(c), samples=samples, seed=s) for c, s in zip(cached, seeds) if not c.exists()]
    if missing:
        blender_jobs.run_with_jobs(blender, blend, "blender_render.py", addon,
                                   dict(width=w, height=h, references=missing), out_dir / "reference_jobs.json",
                                   verbose)
    for c, s in zip(cached, seeds):
        shutil.copyfile(c, out_dir / ("cycles_seed%d.exr" % s))
    images = [metric.read_image(str(c)) for c in cached]
    mean = np.mean(images, axis=0).astype(np.float32)
    path = out_dir / "cycles.exr"
    metric.write_image(str(path), mean)
    noise = dict(samples_per_seed=samples, seeds=len(seeds), dog=float("nan"), rms=float("nan"))
    if len(cached) >= 2:
        d = metric.image_errors(str(cached[0]), str(cached[1]))
        # The mean of k renders has 1/sqrt(k) of one render's noise d / sqrt(2).
        scale = 1.0 / np.sqrt(2.0 * len(cached))
        noise.update(dog=d["dog"] * scale, rms=d["rms"] * scale)
    return path, noise
