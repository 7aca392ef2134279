"""Face-corner values (UV maps) of the input faces carried onto the refined result,
free of `bpy` (tests: tests/model/test_surface_uv.py).

Blender renders a polygon as triangles (its loop triangles) and interpolates
face-corner data such as UVs linearly over each. A result polygon lies inside
one input face (`result.source_face`), so the value at each of its corners is
the input face's value there: the barycentric combination of the corners of
the face's triangle that contains the point. The triangles are Blender's own
(read in export.py from the mesh's loop triangles); without them
`blender_triangles` rebuilds them the way Blender does for triangles and
quads (a fan for larger polygons).

Values are computed per result corner, not per result vertex: a UV map is
face-corner data, and a corner always knows its polygon's source face, so a
vertex shared by polygons of different faces (native/core/hierarchy/output_mesh.cpp
shares vertices only within one side of one input face) would be handled too.
"""

import numpy as np


def flat_loop_order(loop_start, loop_total, mirrored=False):
    """The Blender loop index of every corner of the exported polygon arrays:
    corners gathered in polygon order from loop_start, each polygon reversed
    when the object's transform mirrors (export.py's winding fix)."""
    loop_start = np.asarray(loop_start, dtype=np.int64)
    loop_total = np.asarray(loop_total, dtype=np.int64)
    starts = np.cumsum(loop_total) - loop_total
    k = np.arange(int(loop_total.sum()), dtype=np.int64) - np.repeat(starts, loop_total)
    if mirrored:
        k = np.repeat(loop_total, loop_total) - 1 - k
    return np.repeat(loop_start, loop_total) + k


def loop_values_to_flat(values, flat_loops):
    """Per-loop values (L, k) in the exported corner order."""
    return np.asarray(values)[np.asarray(flat_loops, dtype=np.int64)]


def loop_triangles_to_flat(triangle_loops, flat_loops, loop_count):
    """Blender's loop triangles (T, 3 loop indices) as exported corner indices."""
    flat_of_loop = np.full(int(loop_count), -1, dtype=np.int64)
    flat_of_loop[np.asarray(flat_loops, dtype=np.int64)] = np.arange(len(flat_loops), dtype=np.int64)
    return flat_of_loop[np.asarray(triangle_loops, dtype=np.int64).reshape(-1, 3)]


def blender_triangles(points, face_sizes):
    """(triangles (T, 3) of corner indices, triangle_face (T,)) as Blender splits
    polygons: a quad along its 0-2 diagonal unless that diagonal lies outside
    it (a concave or folded quad: then 1-3), larger polygons as a fan from
    their first corner (Blender ear-clips them; the same for convex ones)."""
    points = np.asarray(points, dtype=np.float64)
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    starts = np.cumsum(face_sizes) - face_sizes
    count = np.maximum(face_sizes - 2, 0)
    tri_face = np.repeat(np.arange(len(face_sizes)), count)
    j = np.arange(int(count.sum()), dtype=np.int64) - np.repeat(np.cumsum(count) - count, count)
    s = starts[tri_face]
    tris = np.column_stack([s, s + j + 1, s + j + 2])
    quads = np.flatnonzero(face_sizes == 4)
    if len(quads):
        q = starts[quads]
        p0, p1, p2, p3 = (points[q + i] for i in range(4))
        # Blender's is_quad_flip_v3_first_third_fast: the 0-2 split is bad when
        # its two triangles face opposite ways (corners 1 and 3 on one side of it).
        n1 = np.cross(p1 - p0, p2 - p0)
        n2 = np.cross(p2 - p0, p3 - p0)
        flip = np.einsum("ij,ij->i", n1, n2) < 0.0
        first = np.flatnonzero(np.isin(tri_face, quads[flip]) & (j == 0))
        qf = q[flip]
        tris[first] = np.column_stack([qf, qf + 1, qf + 3])
        tris[first + 1] = np.column_stack([qf + 1, qf + 2, qf + 3])
    return tris, tri_face


def barycentric(p, a, b, c):
    """Barycentric coordinates (n, 3) of points p in triangles (a, b, c), all (n, 3):
    of p's projection onto the triangle's plane; NaN for degenerate triangles."""
    v0, v1, v2 = b - a, c - a, p - a
    d00 = np.einsum("ij,ij->i", v0, v0)
    d01 = np.einsum("ij,ij->i", v0, v1)
    d11 = np.einsum("ij,ij->i", v1, v1)
    d20 = np.einsum("ij,ij->i", v2, v0)
    d21 = np.einsum("ij,ij->i", v2, v1)
    denom = d00 * d11 - d01 * d01
    ok = denom > 1e-30 * np.maximum(d00 * d11, 1e-300)
    denom = np.where(ok, denom, 1.0)
    v = (d11 * d20 - d01 * d21) / denom
    w = (d00 * d21 - d01 * d20) / denom
    out = np.column_stack([1.0 - v - w, v, w])
    out[~ok] = np.nan
    return out


def interpolate(face_points, face_sizes, triangles, triangle_face, values, query_points, query_face):
    """Values at points inside input faces, as Blender interpolates face-corner data.

    face_points (C, 3): the faces' corners (concatenated, `face_sizes` each);
    triangles (T, 3) corner indices, `triangle_face` (T,) their faces (any order);
    values (C, k) per corner; query_points (Q, 3) with the face each lies in,
    query_face (Q,). Each point takes the barycentric combination of the corners
    of its face's triangle that contains it (the most nearly containing one, for
    a point a rounding outside). A face whose triangles are all degenerate gives
    its corners' mean. Returns (Q, k) float64.
    """
    face_points = np.asarray(face_points, dtype=np.float64)
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    values = np.asarray(values, dtype=np.float64)
    squeeze = values.ndim == 1
    if squeeze:
        values = values[:, None]
    query_points = np.asarray(query_points, dtype=np.float64).reshape(-1, 3)
    query_face = np.asarray(query_face, dtype=np.int64)
    triangles = np.asarray(triangles, dtype=np.int64).reshape(-1, 3)
    triangle_face = np.asarray(triangle_face, dtype=np.int64)
    faces = len(face_sizes)

    # The corners' mean per face: the fallback.
    corner_face = np.repeat(np.arange(faces), face_sizes)
    mean = np.zeros((faces, values.shape[1]))
    np.add.at(mean, corner_face, values)
    mean /= np.maximum(face_sizes, 1)[:, None]
    out = mean[query_face].copy()
    if len(query_face) == 0 or len(triangles) == 0:
        return out[:, 0] if squeeze else out

    # Triangles grouped by face.
    order = np.argsort(triangle_face, kind="stable")
    triangles, triangle_face = triangles[order], triangle_face[order]
    tri_count = np.bincount(triangle_face, minlength=faces)
    tri_start = np.cumsum(tri_count) - tri_count
    # Every (query, triangle of its face) pair, grouped by query.
    per_query = tri_count[query_face]
    pair_query = np.repeat(np.arange(len(query_face)), per_query)
    k = np.arange(int(per_query.sum()), dtype=np.int64) - np.repeat(np.cumsum(per_query) - per_query, per_query)
    pair_tri = tri_start[query_face][pair_query] + k
    corners = triangles[pair_tri]
    bary = barycentric(query_points[pair_query], face_points[corners[:, 0]], face_points[corners[:, 1]],
                       face_points[corners[:, 2]])
    score = np.nan_to_num(bary.min(axis=1), nan=-np.inf)
    # Per query, the pair of highest score (the triangle containing the point).
    best = np.lexsort((-score, pair_query))
    first = np.ones(len(best), dtype=bool)
    first[1:] = pair_query[best][1:] != pair_query[best][:-1]
    chosen = best[first]
    q = pair_query[chosen]
    good = np.isfinite(score[chosen])
    chosen, q = chosen[good], q[good]
    w = bary[chosen]
    c = corners[chosen]
    out[q] = (w[:, 0, None] * values[c[:, 0]] + w[:, 1, None] * values[c[:, 1]]
              + w[:, 2, None] * values[c[:, 2]])
    return out[:, 0] if squeeze else out


def part_corner_queries(face_vertices, face_starts, face_sizes, polygons, source_face, first_face):
    """The corners of result polygons `polygons` (one part's, ascending: the order
    arrays.split_result builds its mesh in): (result vertex of each corner, the
    part's input face of each corner, counted from `first_face`)."""
    polygons = np.asarray(polygons, dtype=np.int64)
    sizes = np.asarray(face_sizes, dtype=np.int64)[polygons]
    offsets = np.cumsum(sizes) - sizes
    k = np.arange(int(sizes.sum()), dtype=np.int64) - np.repeat(offsets, sizes)
    corners = np.repeat(np.asarray(face_starts, dtype=np.int64)[polygons], sizes) + k
    faces = np.repeat(np.asarray(source_face, dtype=np.int64)[polygons], sizes) - int(first_face)
    return np.asarray(face_vertices, dtype=np.int64)[corners], faces


class LoopUVs:
    """The UV maps and loop triangles of one evaluated mesh, per Blender loop
    (export.py reads them; `corners` puts them in the exported corner order)."""

    def __init__(self, layers, render, loop_start, loop_total, triangle_loops, triangle_polygon):
        self.layers = layers                  # {name: (L, 2)} in the mesh's order
        self.render = render                  # name of the render UV map ("" if none)
        self.loop_start = np.asarray(loop_start, dtype=np.int64)
        self.loop_total = np.asarray(loop_total, dtype=np.int64)
        self.triangle_loops = np.asarray(triangle_loops, dtype=np.int64).reshape(-1, 3)
        self.triangle_polygon = np.asarray(triangle_polygon, dtype=np.int64)

    def corners(self, mirrored=False):
        """({name: (C, 2) float32}, triangles (T, 3) corner indices, triangle_face (T,))
        in the exported corner order (polygon order; reversed polygons if mirrored)."""
        flat = flat_loop_order(self.loop_start, self.loop_total, mirrored)
        layers = {name: loop_values_to_flat(uv, flat).astype(np.float32) for name, uv in self.layers.items()}
        loop_count = int((self.loop_start + self.loop_total).max(initial=0))
        triangles = loop_triangles_to_flat(self.triangle_loops, flat, loop_count)
        return layers, triangles, self.triangle_polygon.copy()
