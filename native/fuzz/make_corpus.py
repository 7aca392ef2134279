#!/usr/bin/env python3
"""Writes the seed corpus of the libFuzzer harnesses (native/fuzz/corpus/*):
issue 19's reproducers and a few ordinary cases, in the harnesses' input
layouts (fuzz_input.h and the comment at the top of each fuzz_*.cpp).

The files are committed; rerun after changing a layout:
    python3 native/fuzz/make_corpus.py
"""

import math
import pathlib
import struct

import numpy as np

HERE = pathlib.Path(__file__).resolve().parent
CORPUS = HERE / "corpus"


def u8(v):
    return struct.pack("<B", v & 0xFF)


def u16(v):
    return struct.pack("<H", v & 0xFFFF)


def i64(v):
    return struct.pack("<q", v)


def f64(*vs):
    return b"".join(struct.pack("<d", float(v)) for v in vs)


# --- fuzz_scene ----------------------------------------------------------------------

SOLVE, SAMPLED, TWO_THREADS = 4, 8, 16


def scene_bytes(positions, faces, reflectance=None, emission=None, flags=SOLVE, two_sided=None,
                lights=(), world=(0, 0, 0), sizes=None, oracle=1, quality=0.3, max_elements=128,
                bounces=2, min_area=1e-2, leaf_links=1):
    positions = np.asarray(positions, float).reshape(-1, 3)
    nf = len(faces)
    sizes = [len(f) for f in faces] if sizes is None else sizes
    indices = [i for f in faces for i in f]
    reflectance = np.full((nf, 3), 0.5) if reflectance is None else np.asarray(reflectance, float).reshape(nf, 3)
    emission = np.zeros((nf, 3)) if emission is None else np.asarray(emission, float).reshape(nf, 3)
    if two_sided is not None:
        flags |= 1
    out = [u8(flags), u16(len(positions)), f64(*positions.ravel()), u16(nf)]
    out += [i64(s) for s in sizes]
    out += [u16(len(indices))] + [i64(i) for i in indices]
    out += [f64(*reflectance.ravel()), f64(*emission.ravel())]
    if two_sided is not None:
        out += [u8(int(b)) for b in two_sided]
    out.append(u8(len(lights)))
    for light in lights:
        kind = {"point": 0, "spot": 1, "sun": 2}[light["type"]]
        out += [u8(kind), f64(*light.get("colour", (1, 1, 1))), f64(*light.get("position", (0, 0, 0))),
                f64(*light.get("direction", (0, 0, -1))), f64(light.get("radius", 0.0)),
                f64(light.get("angle", 0.0)), f64(light.get("cos_half_angle", -1.0)),
                f64(light.get("blend_width", 0.0)), u8(light.get("bits", 1))]
    out.append(f64(*world))
    out += [u8(oracle), f64(quality), u16(max_elements - 1), u8(bounces - 1), f64(min_area), u8(leaf_links)]
    return b"".join(out)


def open_room():
    """Floor and three walls of a 4 x 4 x 3 room, facing in, and a ceiling light."""
    p = [(0, 0, 0), (4, 0, 0), (4, 4, 0), (0, 4, 0), (0, 0, 3), (4, 0, 3), (4, 4, 3), (0, 4, 3),
         (1.5, 1.5, 2.99), (2.5, 1.5, 2.99), (2.5, 2.5, 2.99), (1.5, 2.5, 2.99)]
    faces = [[0, 1, 2, 3], [0, 4, 5, 1], [1, 5, 6, 2], [3, 2, 6, 7], [8, 11, 10, 9]]
    emission = [(0, 0, 0)] * 4 + [(5, 5, 5)]
    return p, faces, emission


def scene_seeds():
    rng = np.random.default_rng(19)
    seeds = {}
    p, faces, emission = open_room()
    seeds["room"] = scene_bytes(p, faces, emission=emission)
    seeds["room_sampled_two_threads"] = scene_bytes(p, faces, emission=emission, flags=SOLVE | SAMPLED | TWO_THREADS)
    # Issue 19: sixteen coincident copies of one quad in an open room gave NaN.
    quad = [(1, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)]
    p16 = list(p) + quad * 16
    faces16 = faces + [[12 + 4 * k + i for i in range(4)] for k in range(16)]
    seeds["sixteen_coincident_quads"] = scene_bytes(p16, faces16, emission=emission + [(0, 0, 0)] * 16, quality=0.0)
    seeds["sixteen_shared_index_quads"] = scene_bytes(p + quad, faces + [[12, 13, 14, 15]] * 16,
                                                      emission=emission + [(0, 0, 0)] * 16, quality=0.0)
    # Issue 19: six self-intersecting, non-planar polygons with repeated indices, all emitting.
    pts = rng.uniform(-1, 1, (12, 3))
    polys = [list(rng.choice(12, size=int(rng.integers(4, 8)))) for _ in range(6)]
    for poly in polys:
        poly.append(poly[0])  # a repeated index for certain
    seeds["self_intersecting_emitters"] = scene_bytes(pts, polys, emission=np.full((6, 3), 3.0))
    # Issue 19: face_sizes that add up to the index count only modulo 2^64.
    # 12 indices; the sizes add up to 2^64 + 12, each a valid int64 of at least 3.
    seeds["face_sizes_wrap_2_64"] = scene_bytes(p, [[0, 1, 2, 3]] * 3, sizes=[2 ** 63 - 12, 2 ** 63 - 12, 36],
                                                emission=[(1, 1, 1)] * 3, flags=0)
    # Issue 19: emission 1e300 gave Inf everywhere.
    seeds["emission_1e300"] = scene_bytes(p, faces, emission=[(0, 0, 0)] * 4 + [(1e300, 1e300, 1e300)])
    seeds["emission_1e308"] = scene_bytes(p, faces, emission=[(0, 0, 0)] * 4 + [(1.7e308, 1e308, 1e308)])
    # Scale: 1e-30 and 1e30 rooms, and a room far from the origin.
    for name, scale in (("scale_1e-30", 1e-30), ("scale_1e30", 1e30)):
        seeds[name] = scene_bytes(np.asarray(p) * scale, faces, emission=emission)
    seeds["offset_1e12"] = scene_bytes(np.asarray(p) + 1e12, faces, emission=emission)
    # Slivers, bow-ties, non-planar n-gons, a point face, collinear faces.
    extra = [(0.5, 0.5, 0.5), (3.5, 0.5, 0.5), (2.0, 0.5, 0.5 + 1e-13),            # sliver
             (1, 3, 1), (2, 3, 2), (2, 3, 1), (1, 3, 2),                           # bow-tie
             (3, 3, 1), (3.5, 3.2, 1.4), (3.2, 3.6, 0.7), (2.8, 3.5, 1.3), (2.6, 3.1, 0.9),  # non-planar
             (1, 1, 2), (1, 1, 2), (1, 1, 2),                                        # a point
             (0, 0, 1), (1, 1, 1), (2, 2, 1)]                                        # collinear
    b = len(p)
    hostile = [[b, b + 1, b + 2], [b + 3, b + 4, b + 5, b + 6], [b + 7, b + 8, b + 9, b + 10, b + 11],
               [b + 12, b + 13, b + 14], [b + 15, b + 16, b + 17], [b + 3, b + 3, b + 4, b + 5]]
    seeds["hostile_faces"] = scene_bytes(list(p) + extra, faces + hostile, emission=emission + [(0, 0, 0)] * 6)
    seeds["all_degenerate"] = scene_bytes(extra[12:], [[0, 1, 2], [3, 4, 5]], emission=[(1, 1, 1)] * 2, flags=0)
    # Lights and the world, and bad light values.
    lights = [dict(type="point", colour=(10, 10, 10), position=(2, 2, 2), radius=0.1),
              dict(type="spot", colour=(50, 40, 30), position=(1, 1, 2.5), direction=(0.2, 0.1, -1),
                   cos_half_angle=0.8, blend_width=0.15, bits=3),
              dict(type="sun", colour=(2, 2, 2), direction=(0.3, 0.4, -1), angle=0.05)]
    seeds["lights_and_world"] = scene_bytes(p[:8], faces[:4], emission=[(0, 0, 0)] * 4, lights=lights,
                                            world=(0.2, 0.3, 0.5), two_sided=[1, 1, 1, 0])
    bad = [dict(type="spot", colour=(1, 1, 1), position=(1, 1, 1), direction=(0, 0, 0), cos_half_angle=2.0),
           dict(type="sun", colour=(-1, 1, 1), direction=(0, 0, -1), angle=4.0)]
    seeds["bad_lights"] = scene_bytes(p[:8], faces[:4], lights=bad, world=(-1, 0, 0), flags=0)
    seeds["index_out_of_range"] = scene_bytes(p, [[0, 1, 2, 99]], emission=[(1, 1, 1)], flags=0)
    seeds["negative_size"] = scene_bytes(p, [[0, 1, 2]], sizes=[-3], emission=[(1, 1, 1)], flags=0)
    return seeds


# --- fuzz_kernels and fuzz_visible_polygon ---------------------------------------------

def raw_polygon(vertices):
    vertices = np.asarray(vertices, float)
    return u8(0) + u16(len(vertices) - 3) + f64(*vertices.ravel())


def shaped_polygon(centre, normal, radius, n, jitter=0):
    return u8(1) + u16(n - 3) + f64(*centre) + f64(*normal) + f64(radius) + b"".join(u8(jitter) for _ in range(n))


SQUARE = [(-0.5, -0.5, 2.0), (-0.5, 0.5, 2.0), (0.5, 0.5, 2.0), (0.5, -0.5, 2.0)]
POINT = (0.03, -0.02, 0.0)
NORMAL = (0.1, -0.2, 1.0)


def kernel_seeds():
    seeds = {}
    other = [(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)]
    seeds["square"] = u8(1) + f64(*POINT) + f64(*NORMAL) + raw_polygon(SQUARE) + raw_polygon(other)
    seeds["point_on_vertex"] = u8(1) + f64(*SQUARE[2]) + f64(0, 0, 1) + raw_polygon(SQUARE) + raw_polygon(SQUARE[::-1])
    seeds["point_on_plane"] = u8(1) + f64(0.2, 0.1, 2.0) + f64(0, 0, -1) + raw_polygon(SQUARE) + raw_polygon(other)
    seeds["tiny_polygon"] = (u8(1) + f64(0, 0, 0) + f64(0, 0, 1) + shaped_polygon((0, 0, 1), (0, 0, -1), 1e-12, 6)
                             + shaped_polygon((0, 0, 0), (0, 0, 1), 1.0, 16))
    seeds["sixteen_gon_far"] = (u8(3) + f64(0, 0, 0) + f64(0, 0, 1) + shaped_polygon((0, 0, 1e6), (0, 0, -1), 1.0, 16)
                                + shaped_polygon((0, 0, 0), (0, 0, 1), 1.0, 16))
    # The patch pair that took patch_form_factor's adaptive quadrature to 2^40
    # intervals (fuzz slice, scene seed 4): a quad next to one 1e-12 of its size.
    quad = [(-4.721087714336642e-10, -4.2729275236462975e-09, -4.9719602538841866e-11),
            (5.020433486652835e-09, -3.2097653727151637e-09, -3.2096664895593493e-09),
            (4.3486241962839191e-09, -2.111938573966085e-09, -4.0080257994517912e-09),
            (-3.8029735139882818e-09, 1.1701537641651122e-09, -4.0080257994517904e-09)]
    tiny = [(-2.5779088494727169e-09, -2.3716603553894362e-11, -2.4121532306288478e-09),
            (-2.5779088494722595e-09, -2.3716603554321239e-11, -2.4121532306303872e-09),
            (-2.5779088494707292e-09, -2.3716603554665055e-11, -2.4121532306298371e-09),
            (-2.5779088494711866e-09, -2.3716603554238178e-11, -2.4121532306282978e-09)]
    seeds["patch_pair_tiny_neighbour"] = u8(1) + f64(0, 0, 0) + f64(0, 0, 1) + raw_polygon(quad) + raw_polygon(tiny)
    seeds["bowtie"] = (u8(1) + f64(0, 0, 0) + f64(0, 0, 1) + raw_polygon([SQUARE[0], SQUARE[2], SQUARE[1], SQUARE[3]])
                       + raw_polygon(other))
    seeds["shared_edge"] = (u8(1) + f64(0.5, 0.5, 0.0) + f64(0, 0, 1)
                            + raw_polygon([(0, 0, 0), (1, 0, 0), (1, 0, 1), (0, 0, 1)]) + raw_polygon(other))
    return seeds


def occluder_raw(tri):
    return u8(0) + f64(*np.asarray(tri, float).ravel())


def visible_seeds():
    seeds = {}
    occ = [(0.10, 0.05, 1.00), (0.45, -0.10, 0.90), (0.40, 0.20, 1.15)]
    head = u8(1) + f64(*POINT) + f64(*NORMAL) + raw_polygon(SQUARE)
    seeds["math_occlusion_case"] = head + u16(1) + occluder_raw(occ)
    seeds["no_occluders"] = head + u16(0)
    seeds["touching_point"] = head + u16(2) + u8(2) + f64(*occ[0], *occ[1], *occ[2]) + u8(3) + f64(0, 0, 0) + f64(
        0.3, 0.3, 1.0) + f64(0.2, -0.3, 1.5) + u8(1)
    seeds["coplanar_with_emitter"] = head + u16(1) + occluder_raw([(-1, -1, 2), (1, -1, 2), (0, 1, 2)])
    seeds["sixteen_coincident_occluders"] = head + u16(16) + occluder_raw(occ) * 16
    seeds["between"] = head + u16(3) + b"".join(u8(1) + f64(0.5, 0.3) + f64(*np.random.default_rng(k).normal(size=9))
                                                for k in range(3))
    seeds["edge_on"] = head + u16(1) + occluder_raw([POINT, (0.0, 0.0, 2.0), (0.0, 0.0, 1.0)])
    seeds["hexagon_far"] = (u8(1) + f64(0, 0, 0) + f64(0, 0, 1) + shaped_polygon((0, 0, 1e4), (0, 0, -1), 3.0, 6)
                            + u16(2) + occluder_raw([(-1, -1, 5e3), (1, -1, 5e3), (0, 1, 5e3)])
                            + occluder_raw([(-1, -1, 5e3), (1, -1, 5e3), (0, 1, 5e3)]))
    return seeds


def main():
    for target, seeds in (("scene", scene_seeds()), ("kernels", kernel_seeds()), ("visible_polygon", visible_seeds())):
        folder = CORPUS / target
        folder.mkdir(parents=True, exist_ok=True)
        for name, data in seeds.items():
            (folder / name).write_bytes(data)
        print("%s: %d seeds in %s" % (target, len(seeds), folder))


if __name__ == "__main__":
    main()
