"""Uniform subdivision of a scene's faces for the Cycles-bake comparison (no bpy):
what a Blender user does before baking lighting into vertex colours, subdivide
everything evenly, made from the same arrays the radiosity solver reads.

Every face is cut into a grid of cells no longer than `h` on a side (quads:
bilinear grid; other polygons: each fan triangle into a barycentric grid). A
face's vertices are its own (not shared with neighbours), so a colour never
bleeds across a crease, as in the radiosity output.
"""

import math

import numpy as np


def _quad_grid(p, h):
    """(vertices, quads) of quad p (4, 3) cut into nu x nv cells."""
    nu = max(1, math.ceil(max(np.linalg.norm(p[1] - p[0]), np.linalg.norm(p[2] - p[3])) / h))
    nv = max(1, math.ceil(max(np.linalg.norm(p[3] - p[0]), np.linalg.norm(p[2] - p[1])) / h))
    u = np.linspace(0.0, 1.0, nu + 1)[None, :, None]
    v = np.linspace(0.0, 1.0, nv + 1)[:, None, None]
    verts = ((1 - u) * (1 - v) * p[0] + u * (1 - v) * p[1] + u * v * p[2] + (1 - u) * v * p[3]).reshape(-1, 3)
    idx = np.arange((nu + 1) * (nv + 1)).reshape(nv + 1, nu + 1)
    quads = np.stack([idx[:-1, :-1], idx[:-1, 1:], idx[1:, 1:], idx[1:, :-1]], axis=-1).reshape(-1, 4)
    return verts, quads


def _triangle_grid(p, h):
    """(vertices, triangles) of triangle p (3, 3) cut into n^2 similar triangles."""
    n = max(1, math.ceil(max(np.linalg.norm(p[i] - p[(i + 1) % 3]) for i in range(3)) / h))
    index, verts = {}, []
    for i in range(n + 1):
        for j in range(n + 1 - i):
            index[i, j] = len(verts)
            verts.append(p[0] + (p[1] - p[0]) * i / n + (p[2] - p[0]) * j / n)
    tris = []
    for i in range(n):
        for j in range(n - i):
            tris.append([index[i, j], index[i + 1, j], index[i, j + 1]])
            if i + j < n - 1:
                tris.append([index[i + 1, j], index[i + 1, j + 1], index[i, j + 1]])
    return np.array(verts), np.array(tris)


def subdivide(positions, face_vertices, face_sizes, h):
    """Cut every face into cells of side <= h.

    Returns (vertices (V, 3), polygons: list of index arrays, source face of each polygon)."""
    starts = np.cumsum(face_sizes) - face_sizes
    all_verts, polys, source = [], [], []
    count = 0
    for f, (s, n) in enumerate(zip(starts, face_sizes)):
        p = positions[face_vertices[s:s + n]]
        pieces = [_quad_grid(p, h)] if n == 4 else [_triangle_grid(p[[0, k, k + 1]], h) for k in range(1, n - 1)]
        for verts, cells in pieces:
            all_verts.append(verts)
            polys.extend(cells + count)
            source.extend([f] * len(cells))
            count += len(verts)
    return np.concatenate(all_verts), polys, np.array(source)


def vertex_count(positions, face_vertices, face_sizes, h):
    """Vertices subdivide() makes at cell size h (without making them)."""
    starts = np.cumsum(face_sizes) - face_sizes
    total = 0
    for s, n in zip(starts, face_sizes):
        p = positions[face_vertices[s:s + n]]
        if n == 4:
            nu = max(1, math.ceil(max(np.linalg.norm(p[1] - p[0]), np.linalg.norm(p[2] - p[3])) / h))
            nv = max(1, math.ceil(max(np.linalg.norm(p[3] - p[0]), np.linalg.norm(p[2] - p[1])) / h))
            total += (nu + 1) * (nv + 1)
        else:
            for k in range(1, n - 1):
                t = p[[0, k, k + 1]]
                m = max(1, math.ceil(max(np.linalg.norm(t[i] - t[(i + 1) % 3]) for i in range(3)) / h))
                total += (m + 1) * (m + 2) // 2
    return total


def cell_size_for(positions, face_vertices, face_sizes, target_vertices):
    """The cell size h whose subdivision has about `target_vertices` vertices
    (bisection in log h; the count falls as h grows)."""
    extent = float(np.ptp(positions, axis=0).max())
    lo, hi = extent * 1e-4, extent * 2.0
    for _ in range(40):
        mid = math.sqrt(lo * hi)
        if vertex_count(positions, face_vertices, face_sizes, mid) > target_vertices:
            lo = mid
        else:
            hi = mid
    return hi
