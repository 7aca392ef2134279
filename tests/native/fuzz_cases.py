"""Generated cases for fuzzing `_radiosity` through its Python API (issue 19).

Three parts, used by tests/native/test_fuzz.py (the deterministic slice that
`make test` runs) and by tools/fuzz.py (`make fuzz`, longer and with random
seeds):

- Generators. `scene_case(seed)` builds a small scene as a careless or hostile
  user would (coincident and duplicated faces, non-planar n-gons, bow-ties,
  repeated indices, slivers, near-zero areas, huge and tiny coordinates,
  emission up to 1e300, point/spot/sun light dicts, a world colour, now and
  then an argument the API must refuse) and random solve options;
  `kernel_case(seed)` a batch of direct calls of the kernels (form_factor,
  form_factor_gradient, visible_form_factor exact and sampled,
  visible_polygon, quality_threshold) on hostile geometry. Each is a pure
  function of its seed (numpy's PCG64), so a seed is a reproducer.
- The check. `run_case(rad, kernels, kind, seed)` runs one case: each call must give
  finite, well-formed output or raise ValueError (a clean refusal, counted by
  message class). Anything else is a finding: another exception type,
  non-finite output (positions, radiance, vertex_irradiance, irradiance, F,
  grad F, visible pieces, thresholds) or a malformed result (indices out of
  range, sizes that do not add up, F outside [0, 1] for an unoccluded planar
  polygon).
- The runner. `Campaign` runs cases in worker processes (this file run as a
  script with --worker), one case at a time with a per-case timeout, so a
  segmentation fault, an abort or a hang is caught, reported with its seed,
  and the worker replaced.

Reproduce one case:  python3 tests/native/fuzz_cases.py --path build/addon/radiosity scene 1234
"""

import argparse
import faulthandler
import json
import math
import os
import re
import select
import signal
import subprocess
import sys
import time
import warnings
from collections import Counter

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))

ORACLES = ("standard", "perceptual", "gradient", "noticeable")


class Finding(Exception):
    """A case that did neither finish with finite output nor raise ValueError."""


# --- Geometry ----------------------------------------------------------------------

def _unit(rng):
    v = rng.normal(size=3)
    n = np.linalg.norm(v)
    return v / n if n > 0 else np.array([0.0, 0.0, 1.0])


def _frame(normal):
    helper = np.array([1.0, 0, 0]) if abs(normal[0]) < 0.9 else np.array([0, 1.0, 0])
    t1 = np.cross(helper, normal)
    t1 /= np.linalg.norm(t1)
    return t1, np.cross(normal, t1)


def _convex_polygon(rng, centre, normal, radius, n):
    """A convex planar polygon, counter-clockwise about `normal`."""
    t1, t2 = _frame(normal)
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    if rng.random() < 0.5:  # regular: equal angles
        angles = np.arange(n) * 2 * math.pi / n + rng.uniform(0, 2 * math.pi)
    return np.array([centre + radius * (math.cos(a) * t1 + math.sin(a) * t2) for a in angles])


def _star_polygon(rng, centre, normal, radius, n):
    """A planar, possibly concave polygon (radii vary around the centre)."""
    t1, t2 = _frame(normal)
    angles = np.sort(rng.uniform(0, 2 * math.pi, n))
    radii = radius * rng.uniform(0.2, 1.0, n)
    return np.array([centre + r * (math.cos(a) * t1 + math.sin(a) * t2) for a, r in zip(angles, radii)])


def _axis_quad(rng, scale):
    """An axis-aligned rectangle, either winding."""
    axis = rng.integers(3)
    u, v = [k for k in range(3) if k != axis]
    lo = rng.uniform(-1, 1, 3) * scale
    size = rng.uniform(0.05, 1.5, 2) * scale
    q = np.tile(lo, (4, 1))
    q[1, u] += size[0]
    q[2, u] += size[0]
    q[2, v] += size[1]
    q[3, v] += size[1]
    return q[::-1].copy() if rng.random() < 0.5 else q


class _SceneParts:
    """Vertices and faces collected by the hostile face makers."""

    def __init__(self):
        self.positions = []
        self.faces = []

    def add_vertices(self, points):
        start = len(self.positions)
        self.positions.extend(np.asarray(p, float) for p in points)
        return list(range(start, start + len(points)))

    def add_face(self, indices):
        self.faces.append([int(i) for i in indices])


def _hostile_face(rng, parts, scale):
    """Adds one face of a randomly chosen kind (some of several faces)."""
    kind = rng.choice(["quad", "quad", "triangle", "ngon", "concave", "nonplanar", "bowtie",
                       "repeated", "sliver", "tiny", "collinear", "coincident", "duplicate_indices",
                       "overlap", "through", "point"])
    centre = rng.uniform(-1, 1, 3) * scale
    normal = _unit(rng)
    radius = scale * rng.uniform(0.05, 1.0)
    if kind == "quad":
        parts.add_face(parts.add_vertices(_axis_quad(rng, scale)))
    elif kind == "triangle":
        parts.add_face(parts.add_vertices(rng.uniform(-1, 1, (3, 3)) * scale))
    elif kind == "ngon":
        parts.add_face(parts.add_vertices(_convex_polygon(rng, centre, normal, radius, int(rng.integers(3, 13)))))
    elif kind == "concave":
        parts.add_face(parts.add_vertices(_star_polygon(rng, centre, normal, radius, int(rng.integers(4, 13)))))
    elif kind == "nonplanar":
        poly = _convex_polygon(rng, centre, normal, radius, int(rng.integers(4, 9)))
        poly += np.outer(rng.uniform(-1, 1, len(poly)), normal) * radius * rng.choice([1e-7, 1e-3, 0.3, 1.0])
        parts.add_face(parts.add_vertices(poly))
    elif kind == "bowtie":
        q = _convex_polygon(rng, centre, normal, radius, 4)
        parts.add_face(parts.add_vertices(q[[0, 2, 1, 3]]))
    elif kind == "repeated":
        ids = parts.add_vertices(_convex_polygon(rng, centre, normal, radius, int(rng.integers(3, 6))))
        picks = list(rng.choice(ids, size=int(rng.integers(3, 8))))
        parts.add_face(picks)
    elif kind == "sliver":
        a, b = rng.uniform(-1, 1, (2, 3)) * scale
        c = 0.5 * (a + b) + _unit(rng) * np.linalg.norm(b - a) * rng.choice([1e-12, 1e-9, 1e-6, 1e-3])
        parts.add_face(parts.add_vertices([a, b, c]))
    elif kind == "tiny":
        parts.add_face(parts.add_vertices(_convex_polygon(rng, centre, normal,
                                                          radius * rng.choice([1e-12, 1e-9, 1e-6]), 4)))
    elif kind == "collinear":
        a, b = rng.uniform(-1, 1, (2, 3)) * scale
        parts.add_face(parts.add_vertices([a, 0.5 * (a + b), b, a + 2 * (b - a)]))
    elif kind == "point":
        p = rng.uniform(-1, 1, 3) * scale
        parts.add_face(parts.add_vertices([p, p, p]))
    elif parts.faces:
        source = parts.faces[int(rng.integers(len(parts.faces)))]
        points = np.array([parts.positions[i] for i in source])
        if kind == "coincident":  # copies on their own vertices, some reversed
            for _ in range(int(rng.choice([1, 2, 3, 15]))):
                copy = points[::-1] if rng.random() < 0.5 else points
                parts.add_face(parts.add_vertices(copy))
        elif kind == "duplicate_indices":  # the same vertex indices again
            for _ in range(int(rng.integers(1, 4))):
                parts.add_face(source[::-1] if rng.random() < 0.5 else source)
        elif kind == "overlap":  # shifted in its plane, or a hair off it
            span = np.ptp(points, axis=0).max() + 1e-300
            shift = rng.normal(size=3) * span * rng.choice([0.0, 1e-7, 0.3])
            parts.add_face(parts.add_vertices(points + shift))
        else:  # "through": rotated about its centre so it passes through
            c = points.mean(axis=0)
            axis = _unit(rng)
            angle = rng.uniform(0.1, 3.0)
            k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
            rot = np.eye(3) + math.sin(angle) * k + (1 - math.cos(angle)) * k @ k
            parts.add_face(parts.add_vertices((points - c) @ rot.T + c))
    else:
        parts.add_face(parts.add_vertices(_axis_quad(rng, scale)))


def _room(parts, scale, rng):
    """An open or closed box around the origin (walls facing in), so most
    scenes have something that receives and reflects."""
    lo, hi = -scale * rng.uniform(1, 2, 3), scale * rng.uniform(1, 2, 3)
    x0, y0, z0 = lo
    x1, y1, z1 = hi
    quads = [
        [(x0, y0, z0), (x1, y0, z0), (x1, y1, z0), (x0, y1, z0)],
        [(x0, y0, z1), (x0, y1, z1), (x1, y1, z1), (x1, y0, z1)],
        [(x0, y0, z0), (x0, y0, z1), (x1, y0, z1), (x1, y0, z0)],
        [(x0, y1, z0), (x1, y1, z0), (x1, y1, z1), (x0, y1, z1)],
        [(x0, y0, z0), (x0, y1, z0), (x0, y1, z1), (x0, y0, z1)],
        [(x1, y0, z0), (x1, y0, z1), (x1, y1, z1), (x1, y1, z0)],
    ]
    keep = 6 if rng.random() < 0.3 else int(rng.integers(1, 6))
    for q in quads[:keep]:
        parts.add_face(parts.add_vertices(q))


def _number(rng):
    """A positive number over many magnitudes."""
    return float(10.0 ** rng.uniform(-3, 2))


def _light(rng, scale):
    """One light dict; now and then with a value the API must refuse."""
    kind = rng.choice(["point", "spot", "sun"])
    colour = rng.uniform(0, 1, 3) * _number(rng) * scale * scale
    light = {"type": str(kind)}
    if kind == "sun":
        light["irradiance"] = colour / (scale * scale)
        light["direction"] = _unit(rng)
        if rng.random() < 0.5:
            light["angle"] = float(rng.uniform(0, 3.1))
    else:
        light["intensity"] = colour
        light["position"] = rng.uniform(-1, 1, 3) * scale
        if rng.random() < 0.5:
            light["radius"] = float(rng.choice([0.0, 1e-9, rng.uniform(0, 0.5)]) * scale)
        if rng.random() < 0.3:
            light["shape"] = str(rng.choice(["sphere", "disk"]))
        if kind == "spot":
            light["direction"] = _unit(rng)
            light["cos_half_angle"] = float(rng.choice([-1.0, 1.0, rng.uniform(-1, 1)]))
            if rng.random() < 0.5:
                light["blend_width"] = float(rng.uniform(0, 1))
            if rng.random() < 0.5:
                light["cosine_falloff"] = bool(rng.random() < 0.5)
    if rng.random() < 0.05:  # refused: bad values, a misspelt key, a missing one
        bad = rng.choice(["negative", "zero_direction", "nan", "misspelt", "missing", "angle"])
        if bad == "negative":
            light["irradiance" if kind == "sun" else "intensity"] = -colour
        elif bad == "zero_direction" and "direction" in light:
            light["direction"] = np.zeros(3)
        elif bad == "nan":
            light["position" if kind != "sun" else "direction"] = np.array([np.nan, 0, 1])
        elif bad == "misspelt":
            light["radious"] = 1.0
        elif bad == "missing":
            light.pop("irradiance" if kind == "sun" else "intensity")
        else:
            light["angle" if kind == "sun" else "radius"] = -1.0
    return light


def scene_case(seed):
    """(Scene arguments, solve options) of one generated case: a pure function of seed."""
    rng = np.random.default_rng([19, 1, seed])
    scale = float(10.0 ** rng.choice([rng.uniform(-2, 2), rng.uniform(-6, 6), rng.uniform(-30, 30)],
                                     p=[0.8, 0.15, 0.05]))
    parts = _SceneParts()
    if rng.random() < 0.6:
        _room(parts, scale, rng)
    for _ in range(int(rng.integers(1, 9))):
        _hostile_face(rng, parts, scale)
    # Offset the whole scene now and then (large coordinates, small extent).
    offset = rng.uniform(-1, 1, 3) * scale * rng.choice([0.0, 0.0, 10.0, 1e6])
    positions = np.array(parts.positions, float) + offset
    faces = parts.faces[:40]
    nf = len(faces)
    face_vertices = np.array([i for f in faces for i in f], np.int64)
    face_sizes = np.array([len(f) for f in faces], np.int64)
    reflectance = rng.uniform(0, 1, (nf, 3))
    reflectance[rng.random(nf) < 0.1] = 1.0
    reflectance[rng.random(nf) < 0.1] = 0.0
    emission = np.zeros((nf, 3))
    emitting = rng.random(nf) < rng.choice([0.1, 0.3, 1.0])
    emission[emitting] = rng.uniform(0, 1, (int(emitting.sum()), 3)) * _number(rng)
    if rng.random() < 0.05:  # extreme emission (issue 19: 1e300 gave Inf everywhere)
        emission[emitting] *= float(rng.choice([1e-300, 1e-30, 1e30, 1e300]))
    two_sided = None if rng.random() < 0.5 else rng.random(nf) < 0.7
    occludes = None if rng.random() < 0.7 else rng.random(nf) < 0.8
    if occludes is not None and seed % 10:
        # A face that casts no shadow stands for a light: it must not reflect
        # (refused otherwise, which every tenth seed still tries).
        reflectance = np.where(occludes[:, None], reflectance, 0.0)
    lights = None
    if rng.random() < 0.4:
        lights = [_light(rng, scale) for _ in range(int(rng.integers(0, 4)))]
    world = None if rng.random() < 0.7 else rng.uniform(0, 1, 3) * _number(rng)
    if not emitting.any() and not lights and world is None:
        emission[0] = 1.0  # mostly something to solve; the no-emitter error is its own case below
    args = dict(positions=positions, face_vertices=face_vertices, face_sizes=face_sizes,
                reflectance=reflectance, emission=emission, two_sided=two_sided, occludes=occludes,
                lights=lights, world=world)
    if rng.random() < 0.06:
        _break_arguments(rng, args)
    options = dict(oracle=str(rng.choice(ORACLES)),
                   quality=float(rng.choice([0.0, rng.uniform(0, 0.6), rng.uniform(0, 1)], p=[0.3, 0.5, 0.2])),
                   visibility=str(rng.choice(["exact", "sampled"])),
                   threads=int(rng.integers(1, 3)),
                   min_element_area=float(10.0 ** rng.uniform(-4, -1)),
                   leaf_links=str(rng.choice(["near", "none", "all"])))
    options["max_elements"] = int(rng.choice([rng.integers(1, 50), rng.integers(50, 600)]))
    if options["visibility"] == "sampled":
        options["rays"] = int(rng.integers(1, 17))
    if rng.random() < 0.4:
        options["bounces"] = int(rng.integers(1, 6))
    if rng.random() < 0.2:
        options["cluster_separation"] = float(rng.choice([1.5, 2.0, 6.0, math.inf]))
    if rng.random() < 0.03:  # options the API must refuse
        key, value = [("quality", -0.5), ("quality", math.nan), ("rays", 0), ("bounces", 0),
                      ("threads", 0), ("min_element_area", 0.0), ("max_elements", 0),
                      ("oracle", "bf"), ("visibility", "none"), ("leaf_links", "some"),
                      ("cluster_separation", 0.5), ("time_budget", -1.0)][int(rng.integers(12))]
        options[key] = value
    return args, options


def _break_arguments(rng, args):
    """Makes the Scene arguments invalid in one of the ways the API must refuse."""
    what = int(rng.integers(9))
    nf = len(args["face_sizes"])
    if what == 0:
        args["face_vertices"] = args["face_vertices"].copy()
        args["face_vertices"][-1] = len(args["positions"]) + int(rng.integers(0, 5))
    elif what == 1:
        args["face_sizes"] = args["face_sizes"].copy()
        args["face_sizes"][0] = int(rng.integers(-3, 3))
    elif what == 2 and nf >= 3:  # sizes that add up to the index count only modulo 2^64
        sizes = args["face_sizes"].copy()  # each at most 12 before
        sizes[0] += 2 ** 63 - 16
        sizes[1] += 2 ** 63 - 16
        sizes[2] += 32
        args["face_sizes"] = sizes
    elif what in (2, 3):
        args["positions"] = args["positions"].copy()
        args["positions"][int(rng.integers(len(args["positions"])))] = rng.choice([np.nan, np.inf, -np.inf])
    elif what == 4:
        args["reflectance"] = args["reflectance"].copy()
        args["reflectance"][0, 0] = float(rng.choice([-0.1, 1.5, np.nan]))
    elif what == 5:
        args["emission"] = args["emission"].copy()
        args["emission"][0, 1] = float(rng.choice([-1.0, np.inf, np.nan]))
    elif what == 6:
        args["emission"] = np.zeros((nf, 3))
        args["lights"], args["world"] = None, None
    elif what == 7:
        args["reflectance"] = args["reflectance"][:max(0, nf - 1)]
    else:
        args["world"] = np.array([rng.choice([-1.0, np.nan, np.inf]), 0.0, 0.0])


# --- Kernels -----------------------------------------------------------------------

def _kernel_polygon(rng, scale):
    """An emitter polygon: convex planar mostly, sometimes degenerate or wrong."""
    centre = rng.uniform(-1, 1, 3) * scale
    normal = _unit(rng)
    radius = scale * float(10.0 ** rng.uniform(-3, 0.5))
    kind = rng.choice(["convex", "convex", "convex", "square", "concave", "nonplanar", "degenerate", "tiny"])
    if kind == "square":
        return np.array([[-0.5, -0.5, 2.0], [-0.5, 0.5, 2.0], [0.5, 0.5, 2.0], [0.5, -0.5, 2.0]]) * scale
    if kind == "concave":
        return _star_polygon(rng, centre, normal, radius, int(rng.integers(4, 9)))
    if kind == "nonplanar":
        return rng.uniform(-1, 1, (int(rng.integers(4, 7)), 3)) * scale
    if kind == "degenerate":
        a, b = rng.uniform(-1, 1, (2, 3)) * scale
        return np.array([a, b, 0.5 * (a + b)])
    if kind == "tiny":
        radius *= 1e-9
    return _convex_polygon(rng, centre, normal, radius, int(rng.integers(3, 9)))


def _kernel_point(rng, polygon, scale):
    """A receiver point: anywhere, close to the emitter, on its plane, on a vertex or edge."""
    kind = rng.choice(["free", "free", "near", "vertex", "edge", "plane", "centre"])
    if kind == "vertex":
        return polygon[int(rng.integers(len(polygon)))].copy()
    if kind == "edge":
        i = int(rng.integers(len(polygon)))
        t = rng.uniform()
        return (1 - t) * polygon[i] + t * polygon[(i + 1) % len(polygon)]
    if kind == "plane":
        return polygon[0] + rng.uniform(-1, 1) * (polygon[1] - polygon[0]) + rng.uniform(-1, 1) * (polygon[2] - polygon[0])
    if kind == "centre":
        return polygon.mean(axis=0) + _unit(rng) * scale * float(10.0 ** rng.uniform(-12, 0))
    if kind == "near":
        return polygon.mean(axis=0) + _unit(rng) * scale * float(10.0 ** rng.uniform(-6, 0))
    return rng.uniform(-2, 2, 3) * scale


def _occluders(rng, point, polygon, scale):
    """(m, 3, 3) triangles between the point and the emitter, around them, degenerate, coplanar."""
    m = int(rng.choice([0, 1, 2, 3, 5, 8, 16]))
    tris = []
    centre = polygon.mean(axis=0)
    for _ in range(m):
        kind = rng.choice(["between", "between", "random", "coplanar", "degenerate", "touching", "edge_on"])
        if kind == "between":
            c = point + rng.uniform(0.05, 0.95) * (centre - point)
            size = np.linalg.norm(centre - point) * rng.uniform(0.01, 0.6)
            tris.append(c + rng.normal(size=(3, 3)) * size)
        elif kind == "random":
            tris.append(rng.uniform(-2, 2, (3, 3)) * scale)
        elif kind == "coplanar":
            k = rng.integers(len(polygon), size=3)
            tris.append(polygon[k] + rng.uniform(-0.5, 0.5, (3, 1)) * (polygon[1] - polygon[0]))
        elif kind == "degenerate":
            a = rng.uniform(-1, 1, 3) * scale
            tris.append(np.array([a, a, a + rng.normal(size=3) * scale]))
        elif kind == "touching":  # a vertex on the point or on the emitter
            tri = point + rng.normal(size=(3, 3)) * scale * 0.3
            tri[0] = point if rng.random() < 0.5 else polygon[int(rng.integers(len(polygon)))]
            tris.append(tri)
        else:  # in a plane through the point
            d = centre - point
            side = _unit(rng)
            tris.append(np.array([point + 0.3 * d, point + 0.6 * d, point + 0.5 * d + side * 1e-12 * scale]))
    return np.array(tris, float).reshape(-1, 3, 3)


def kernel_case(seed, calls=10):
    """`calls` kernel calls as (function name, args, kwargs): a pure function of seed."""
    rng = np.random.default_rng([19, 2, seed])
    out = []
    for _ in range(calls):
        scale = float(10.0 ** rng.choice([rng.uniform(-2, 2), rng.uniform(-8, 8)], p=[0.85, 0.15]))
        polygon = _kernel_polygon(rng, scale)
        point = _kernel_point(rng, polygon, scale)
        normal = _unit(rng) if rng.random() < 0.97 else np.zeros(3)
        if rng.random() < 0.3:  # facing the emitter
            d = polygon.mean(axis=0) - point
            if np.linalg.norm(d) > 0:
                normal = d / np.linalg.norm(d)
        if rng.random() < 0.02:
            point = point.copy()
            point[int(rng.integers(3))] = rng.choice([np.nan, np.inf])
        name = rng.choice(["form_factor", "form_factor_gradient", "visible_form_factor", "visible_form_factor",
                           "visible_polygon", "quality_threshold"])
        if name == "quality_threshold":
            q = float(rng.choice([0.0, 1.0, rng.uniform(0, 1), rng.uniform(-1, 2), np.nan]))
            out.append((name, (str(rng.choice(ORACLES + ("x",))), q), {}))
        elif name in ("form_factor", "form_factor_gradient"):
            out.append((name, (point, normal, polygon), {}))
        elif name == "visible_polygon":
            out.append((name, (point, normal, polygon, _occluders(rng, point, polygon, scale)), {}))
        else:
            occ = _occluders(rng, point, polygon, scale)
            kwargs = dict(mode=str(rng.choice(["exact", "sampled"])), rays=int(rng.choice([1, 4, 16, 64])))
            if len(occ) and rng.random() < 0.5:
                kwargs["faces"] = rng.integers(0, 4, len(occ))
                kwargs["own_faces"] = tuple(int(f) for f in rng.integers(0, 4, int(rng.integers(0, 3))))
            out.append((name, (point, normal, polygon, occ), kwargs))
    return out


# --- The check ---------------------------------------------------------------------

def _require_finite(name, array):
    a = np.asarray(array, float)
    if not np.all(np.isfinite(a)):
        bad = np.argwhere(~np.isfinite(a))
        raise Finding("non-finite %s: %d of %d values (first at %s)" % (name, len(bad), a.size, bad[0].tolist()))


def check_result(result, face_count):
    """Finite output and a well-formed mesh."""
    for name in ("positions", "radiance", "vertex_irradiance", "irradiance"):
        _require_finite(name, getattr(result, name))
    v = len(result.positions)
    sizes = np.asarray(result.face_sizes)
    corners = np.asarray(result.face_vertices)
    if result.radiance.shape != (v, 3) or result.vertex_irradiance.shape != (v, 3):
        raise Finding("radiance or vertex_irradiance does not have one row per vertex")
    if len(sizes) and sizes.min() < 3:
        raise Finding("an output polygon has fewer than 3 vertices")
    if int(sizes.sum()) != len(corners):
        raise Finding("output face_sizes add up to %d, face_vertices has %d" % (sizes.sum(), len(corners)))
    if len(corners) and (corners.min() < 0 or corners.max() >= v):
        raise Finding("output face_vertices out of range")
    source = np.asarray(result.source_face)
    if len(source) != len(sizes) or (len(source) and (source.min() < 0 or source.max() >= face_count)):
        raise Finding("source_face out of range")
    if result.irradiance.shape != (len(sizes), 3):
        raise Finding("irradiance does not have one row per polygon")


def _run_scene(rad, seed):
    args, options = scene_case(seed)
    scene = rad.Scene(**args)
    result = rad.solve(scene, **options)
    check_result(result, len(args["face_sizes"]))


def planar_convex(polygon):
    """Planar and convex as bind_visibility.cpp's require_planar_convex judges it."""
    p = np.asarray(polygon, float)
    normal = sum(np.cross(p[i] - p[0], p[i + 1] - p[0]) for i in range(1, len(p) - 1))
    length = np.linalg.norm(normal)
    diameter = max(np.linalg.norm(a - b) for a in p for b in p)
    if not (length > 0 and np.all(np.abs((p - p[0]) @ (normal / length)) <= 1e-9 * diameter)):
        return False
    k = len(p)
    return all(np.dot(np.cross(p[(i + 1) % k] - p[i], p[(i + 2) % k] - p[(i + 1) % k]), normal / length)
               >= -1e-12 * diameter * diameter for i in range(k))


def run_kernel_call(rad, kernels, name, args, kwargs):
    """One call of kernel_case's: quality_threshold of `rad` (_radiosity), the rest
    of `kernels` (the test-only _radiosity_kernels)."""
    out = getattr(rad if name == "quality_threshold" else kernels, name)(*args, **kwargs)
    # F to a planar convex polygon (what the solver passes) is a share of the
    # receiver's hemisphere. The kernels take non-planar and concave ones too;
    # what they give then is no F (a concave pentagon across the receiver's
    # horizon gave -3e-4: kernel seed 695).
    bounded = name in ("form_factor", "form_factor_gradient") and planar_convex(args[2])
    if name == "quality_threshold":
        # Quality 0 is "no refinement": an infinite threshold, by definition.
        if args[1] == 0.0:
            if out != float("inf"):
                raise Finding("quality 0 gave threshold %r, not inf" % out)
        elif not (np.isfinite(out) and out > 0):
            raise Finding("threshold %r at quality %r is not finite and positive" % (out, args[1]))
    elif name == "form_factor":
        _require_finite("F", out)
        if bounded and not -1e-9 <= out <= 1 + 1e-9:
            raise Finding("unoccluded F = %r outside [0, 1]" % out)
    elif name == "visible_polygon":
        pieces, _ = out
        for piece in pieces:
            _require_finite("visible piece positions", piece["positions"])
            _require_finite("visible piece anchors", piece["anchors"])
    else:
        f, g = out
        _require_finite("F", f)
        _require_finite("grad F", g)
        if bounded and not -1e-9 <= f <= 1 + 1e-9:
            raise Finding("unoccluded F = %r outside [0, 1]" % f)


def run_case(rad, kernels, kind, seed):
    """Runs one case: (calls made, clean ValueErrors by message class, findings).

    A scene case is one Scene() and solve(); a kernel case is kernel_case(seed)'s
    calls, each checked on its own (a finding in one does not stop the rest)."""
    errors, findings = Counter(), []
    if kind == "scene":
        try:
            _run_scene(rad, seed)
        except ValueError as err:
            errors[message_class(err)] += 1
        except Finding as err:
            findings.append(str(err))
        except Exception as err:  # noqa: BLE001  (anything but ValueError is a finding)
            findings.append("%s: %s" % (type(err).__name__, err))
        return 1, errors, findings
    calls = kernel_case(seed)
    for index, (name, args, kwargs) in enumerate(calls):
        try:
            run_kernel_call(rad, kernels, name, args, kwargs)
        except ValueError as err:
            errors["%s: %s" % (name, message_class(err))] += 1
        except Finding as err:
            findings.append("call %d (%s): %s" % (index, name, err))
        except Exception as err:  # noqa: BLE001
            findings.append("call %d (%s): %s: %s" % (index, name, type(err).__name__, err))
    return len(calls), errors, findings


def message_class(err):
    """A ValueError's message with its numbers and names of indices taken out."""
    text = str(err).splitlines()[0] if str(err) else type(err).__name__
    text = re.sub(r"\[\d+\]", "[i]", text)
    text = re.sub(r"-?\b\d[\d.]*(e[+-]?\d+)?\b|-?inf\b|nan\b", "N", text)
    text = re.sub(r"'[^']*'", "'...'", text)
    return text[:90]


# --- Worker and runner --------------------------------------------------------------

def worker(paths):
    """Reads `KIND SEED` lines, answers one JSON line per case."""
    for p in paths:
        sys.path.insert(0, p)
    import _radiosity as rad  # noqa: E402
    try:
        from kernels_module import kernels  # noqa: E402  (None where not built: no kernel cases then)
    except ImportError:  # this worker's paths hold no build/study: test_fuzz then runs no kernel cases
        kernels = None
    # stderr is for what a crash leaves: Python's traceback at the fault, a
    # sanitizer's report; not for numpy's warnings about hostile generated values.
    faulthandler.enable()
    np.seterr(all="ignore")
    warnings.simplefilter("ignore")
    for line in sys.stdin:
        kind, seed = line.split()
        seed = int(seed)
        calls, errors, findings = run_case(rad, kernels, kind, seed)
        reply = {"seed": seed, "calls": calls, "errors": dict(errors), "findings": findings}
        sys.stdout.write(json.dumps(reply) + "\n")
        sys.stdout.flush()


class Campaign:
    """Runs cases in `jobs` worker processes, each case with a timeout.

    A worker that dies (signal, abort, sanitizer report) or does not answer in
    time is recorded as a crash or hang of the case it was running and is
    replaced. `findings` lists (kind, seed, what) of every case that failed."""

    def __init__(self, module_paths, jobs=2, timeout=60.0, env=None, python=sys.executable):
        self.module_paths = list(module_paths)
        self.jobs, self.timeout, self.python = jobs, timeout, python
        self.env = dict(os.environ if env is None else env)
        self.env["PYTHONHASHSEED"] = "0"
        self.cases = Counter()     # kind -> cases run
        self.calls = Counter()     # kind -> API calls made (scenes: 1 per case)
        self.errors = Counter()    # ValueError message class -> count
        self.findings = []         # (kind, seed, what)
        self.seconds = 0.0

    def _start(self):
        cmd = [self.python, os.path.abspath(__file__), "--worker"]
        for p in self.module_paths:
            cmd += ["--path", p]
        return subprocess.Popen(cmd, stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                env=self.env, text=True, bufsize=1, start_new_session=True)

    @staticmethod
    def _stop(proc):
        if proc.poll() is None:
            try:
                if hasattr(os, "killpg"):
                    os.killpg(proc.pid, signal.SIGKILL)
                else:   # Windows (the Windows module's tests run under Wine): no process groups
                    proc.kill()
            except ProcessLookupError:
                pass
        proc.wait()

    def run(self, cases, deadline=None):
        """Runs (kind, seed) pairs; stops early at `deadline` (time.monotonic())."""
        start = time.monotonic()
        pending = list(cases)[::-1]
        slots = [None] * self.jobs   # per slot: [proc, case, started]
        try:
            while pending or any(s and s[1] for s in slots):
                for i in range(self.jobs):
                    if slots[i] is None:
                        slots[i] = [self._start(), None, 0.0]
                    if slots[i][1] is None and pending and (deadline is None or time.monotonic() < deadline):
                        case = pending.pop()
                        slots[i][1], slots[i][2] = case, time.monotonic()
                        try:
                            slots[i][0].stdin.write("%s %d\n" % case)
                            slots[i][0].stdin.flush()
                        except BrokenPipeError:
                            pass  # found dead below
                if deadline is not None and time.monotonic() >= deadline:
                    pending = []
                busy = [s for s in slots if s[1] is not None]
                if not busy:
                    break
                ready, _, _ = select.select([s[0].stdout for s in busy], [], [], 0.5)
                for i, slot in enumerate(slots):
                    if slot is None or slot[1] is None:
                        continue
                    proc, case, started = slot
                    if proc.stdout in ready:
                        line = proc.stdout.readline()
                        if line:
                            self._record(case, json.loads(line))
                            slot[1] = None
                            continue
                        self._crashed(proc, case)
                        slots[i] = None
                    elif time.monotonic() - started > self.timeout:
                        self._stop(proc)
                        self.findings.append((case[0], case[1], "hang: no answer in %.0f s" % self.timeout))
                        self.cases[case[0]] += 1
                        slots[i] = None
        finally:
            for slot in slots:
                if slot is not None:
                    self._stop(slot[0])
        self.seconds += time.monotonic() - start

    def _record(self, case, reply):
        self.cases[case[0]] += 1
        self.calls[case[0]] += reply["calls"]
        self.errors.update(reply["errors"])
        self.findings.extend((case[0], case[1], what) for what in reply["findings"])

    def _crashed(self, proc, case):
        proc.wait()
        stderr = proc.stderr.read()
        code = proc.returncode
        what = ("signal %s" % signal.Signals(-code).name) if code < 0 else "exit code %d" % code
        lines = stderr.strip().splitlines()
        # What a sanitizer or faulthandler said first, then where Python was.
        heads = [line for line in lines
                 if re.search(r"runtime error:|ERROR: \w+Sanitizer|SUMMARY: \w+Sanitizer|Fatal Python error", line)]
        python = [line for line in lines if line.lstrip().startswith("File ")][:4]
        self.findings.append((case[0], case[1], "crash (%s)\n%s" % (what, "\n".join(heads[:4] + python))))
        self.cases[case[0]] += 1

    def summary(self, examples=3):
        """Counts, ValueErrors by message class, findings by class with a few seeds each."""
        lines = ["%d generated scenes, %d kernel calls (%d kernel cases) in %.1f s"
                 % (self.cases["scene"], self.calls["kernel"], self.cases["kernel"], self.seconds),
                 "%d findings (crashes, hangs, non-finite or malformed output)" % len(self.findings),
                 "%d clean ValueErrors, by message class:" % sum(self.errors.values())]
        for message, count in sorted(self.errors.items(), key=lambda kv: (-kv[1], kv[0])):
            lines.append("  %6d  %s" % (count, message))
        classes = {}
        for kind, seed, what in self.findings:
            key = (kind, re.sub(r"-?N", "N", message_class(re.sub(r"^call \d+ ", "", what.splitlines()[0]))))
            classes.setdefault(key, []).append((seed, what))
        for (kind, key), cases in sorted(classes.items(), key=lambda kv: -len(kv[1])):
            lines.append("FINDING x%d (%s) %s" % (len(cases), kind, key))
            for seed, what in cases[:examples]:
                lines.append("  seed %d: %s" % (seed, what.replace("\n", "\n    ")))
                lines.append("    reproduce: python3 tests/native/fuzz_cases.py --path BUILD/addon/radiosity "
                             "--path BUILD/study %s %d" % (kind, seed))
        return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--worker", action="store_true", help="answer `KIND SEED` lines on stdin")
    parser.add_argument("--path", action="append", default=[],
                        help="directory holding _radiosity or _radiosity_kernels (repeatable)")
    parser.add_argument("--show", action="store_true", help="print the case's arguments")
    parser.add_argument("kind", nargs="?", choices=["scene", "kernel"])
    parser.add_argument("seed", nargs="?", type=int)
    args = parser.parse_args(argv)
    if args.worker:
        worker(args.path)
        return 0
    if args.kind is None or args.seed is None:
        parser.error("give KIND and SEED to reproduce one case")
    for p in args.path:
        sys.path.insert(0, p)
    import _radiosity as rad  # noqa: E402
    kernels = None
    if args.kind == "kernel":
        import _radiosity_kernels as kernels  # noqa: E402
    if args.show:
        np.set_printoptions(precision=17, threshold=10 ** 6)
        print(scene_case(args.seed) if args.kind == "scene" else kernel_case(args.seed))
    calls, errors, findings = run_case(rad, kernels, args.kind, args.seed)
    print("%d call(s); clean ValueErrors: %s" % (calls, dict(errors)))
    for what in findings:
        print("FINDING: %s" % what)
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
