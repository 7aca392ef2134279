#!/usr/bin/env python3
"""Relighting benchmark: a solve, then the same geometry solved again with a
SolveReuse after only the lighting changed, against the first solve's time and
against a solve of the new lighting from nothing.

    /usr/bin/python3 bench/relight_bench.py [--build build] [--blender blender]
                                            [--quality 0.5] [--repeats 3] [--quick]

Three changes per bundled scene and oracle (changes() says which). Times are medians of --repeats runs, each making the Scene
(validation, patches and contact meshing: what the add-on pays too); `ratio`
is the relight's median over the first solve's. `max_difference` compares the
relit result with the solve from nothing: for "strength" the largest vertex
radiance difference over the brightest vertex when the meshes are the same
(expected for "strength"), otherwise the largest difference of a face's mean gathered light over the
brightest face's (their meshes differ where the new radiances refine).
Writes <build>/bench/relight.csv and relight.md.
"""

import argparse
import pathlib
import statistics
import sys
import time

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
from solver_bench import BUNDLED, export_bundled, oracles, write_results  # noqa: E402


def make_scene(rad, arrays, emission=None, reflectance=None):
    a = arrays
    args = (a["positions"], a["face_vertices"], a["face_sizes"],
            a["reflectance"] if reflectance is None else reflectance,
            a["emission"] if emission is None else emission, a["two_sided"])
    return rad.Scene(*args, occludes=a["occludes"]) if "occludes" in a else rad.Scene(*args)


def face_areas(arrays):
    positions, sizes = arrays["positions"], arrays["face_sizes"]
    starts = np.concatenate([[0], np.cumsum(sizes)[:-1]])
    areas = []
    for start, size in zip(starts, sizes):
        p = positions[arrays["face_vertices"][start:start + size]]
        areas.append(0.5 * np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0)))
    return np.array(areas)


def face_light(result, faces):
    """Area-weighted mean gathered light per input face (both sides together)."""
    polygons = np.split(np.asarray(result.face_vertices), np.cumsum(result.face_sizes)[:-1])
    pos = np.asarray(result.positions)
    areas = np.array([0.5 * np.linalg.norm(np.cross(pos[p[1:-1]] - pos[p[0]], pos[p[2:]] - pos[p[0]]).sum(axis=0))
                      for p in polygons])
    light = np.asarray(result.irradiance).mean(axis=1) * areas
    source = np.asarray(result.source_face)
    total = np.bincount(source, light, minlength=faces)
    area = np.bincount(source, areas, minlength=faces)
    return np.divide(total, area, out=np.zeros(faces), where=area > 0)


def luminance(rgb):
    return np.asarray(rgb, float) @ (0.2126, 0.7152, 0.0722)


def changes(arrays):
    """The lighting changes measured: name -> keyword arguments of make_scene.
    "strength": every emitter 1.5 times as strong; "hue": the largest
    reflecting face warm-tinted at the same luminance; "darker": its
    reflectance halved, which lowers the scene's adaptation level, so every
    oracle asks for more refinement."""
    emitting = np.any(arrays["emission"] > 0, axis=1)
    reflecting = np.flatnonzero(np.any(arrays["reflectance"] > 0, axis=1) & ~emitting)
    wall = reflecting[np.argmax(face_areas(arrays)[reflecting])]
    base = np.array(arrays["reflectance"], float)
    hue, darker = base.copy(), base.copy()
    tint = np.array((1.3, 0.95, 0.7))
    hue[wall] = np.minimum(tint * luminance(base[wall]) / luminance(tint), 1.0)
    darker[wall] = 0.5 * base[wall]
    return {"strength": dict(emission=np.array(arrays["emission"], float) * 1.5),
            "hue": dict(reflectance=hue), "darker": dict(reflectance=darker)}


def measure(rad, arrays, oracle, quality, change, repeats):
    first_times, relight_times, relit = [], [], None
    for _ in range(repeats):
        reuse = rad.SolveReuse()
        start = time.perf_counter()
        rad.solve(make_scene(rad, arrays), oracle=oracle, quality=quality, reuse=reuse)
        first_times.append(time.perf_counter() - start)
        start = time.perf_counter()
        relit = rad.solve(make_scene(rad, arrays, **change), oracle=oracle, quality=quality, reuse=reuse)
        relight_times.append(time.perf_counter() - start)
    fresh = rad.solve(make_scene(rad, arrays, **change), oracle=oracle, quality=quality)
    if relit.radiance.shape == fresh.radiance.shape and np.array_equal(relit.positions, fresh.positions):
        difference = float(np.max(np.abs(relit.radiance - fresh.radiance)) / np.max(fresh.radiance))
        same_mesh = True
    else:
        faces = len(arrays["face_sizes"])
        a, b = face_light(relit, faces), face_light(fresh, faces)
        difference = float(np.max(np.abs(a - b)) / np.max(b))
        same_mesh = False
    first, again = statistics.median(first_times), statistics.median(relight_times)
    return dict(first_s=round(first, 3), relight_s=round(again, 3), ratio=round(again / first, 3),
                reused=relit.stats["reused"], leaves_fresh=fresh.stats["leaves"],
                leaves_relit=relit.stats["leaves"], iterations=relit.stats["iterations"],
                same_mesh=same_mesh, max_difference=float("%.2g" % difference))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--build", default="build")
    parser.add_argument("--blender", default="blender")
    parser.add_argument("--quality", type=float, default=0.5)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--quick", action="store_true", help="cube and office only, one repeat")
    args = parser.parse_args()
    sys.path.insert(0, str(ROOT / args.build / "addon" / "radiosity"))
    import _radiosity as rad

    rows = []
    for name in ("cube", "office") if args.quick else BUNDLED:
        arrays = dict(np.load(export_bundled(name, args.build, args.blender).path))
        for oracle in oracles(rad):
            for change_name, change in changes(arrays).items():
                row = dict(scene=name, oracle=oracle, quality=args.quality, change=change_name,
                           **measure(rad, arrays, oracle, args.quality, change, 1 if args.quick else args.repeats))
                rows.append(row)
                print(row, flush=True)
    write_results(rows, ROOT / args.build / "bench", "relight")


if __name__ == "__main__":
    main()
