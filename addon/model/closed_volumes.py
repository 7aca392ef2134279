"""Closed objects with nothing inside them: their inside sides are left out.

A mesh that is closed (every edge shared by exactly two of its faces, walked
in opposite directions) with its normals pointing out encloses a volume that
light cannot enter or leave. Its inside sides exchange light only among
themselves and with what lies within: where nothing does (no vertex of
another object, no light, not the camera), they stay dark whatever happens
outside, and nothing outside can see them. Every mesh face is exported
two-sided, and the inside faces of a dense closed object all face each other:
four fifths of the links of bench/tessellated_room.py (native/README.md,
"Light inside closed objects"). Leaving those sides out changes no light that
can be seen.

Plain numpy, no bpy (tests/model/test_closed_volumes.py).
"""

import numpy as np

# A winding number above this is inside: 1 within the volume, 0 outside (on
# the surface it is anything between; on_surface finds those points first).
INSIDE_WINDING = 0.75
# Closed surfaces enclosing less than this share of their bounding box's
# diagonal cubed are flat (two faces back to back), not volumes.
MIN_RELATIVE_VOLUME = 1e-9
# Points this close to the surface, as a share of the object's size, lie on it.
ON_SURFACE = 1e-7
# Point-triangle pairs one object's test may cost (a few seconds); beyond, it keeps both sides.
MAX_PAIRS = 50_000_000


def _polygon_edges(face_vertices, face_sizes):
    """(start, end) vertex of every edge of every polygon, in winding order."""
    starts = np.cumsum(face_sizes) - face_sizes
    k = np.arange(len(face_vertices)) - np.repeat(starts, face_sizes)
    nxt = np.repeat(starts, face_sizes) + (k + 1) % np.repeat(face_sizes, face_sizes)
    return face_vertices, face_vertices[nxt]


def _fan_triangles(face_vertices, face_sizes):
    """(T, 3) vertex indices of the polygons fanned from their first corner."""
    starts = np.cumsum(face_sizes) - face_sizes
    per = np.maximum(face_sizes - 2, 0)
    first = np.repeat(starts, per)
    k = np.arange(per.sum()) - np.repeat(np.cumsum(per) - per, per)
    return np.stack([face_vertices[first], face_vertices[first + k + 1], face_vertices[first + k + 2]], axis=1)


def is_closed(face_vertices, face_sizes):
    """Whether the polygons form a closed, consistently wound surface."""
    a, b = _polygon_edges(face_vertices, face_sizes)
    if len(a) == 0:
        return False
    n = int(max(a.max(), b.max())) + 1
    directed = a * n + b
    if len(np.unique(directed)) != len(directed):
        return False
    return bool(np.isin(b * n + a, directed).all())


def winding_numbers(points, corners):
    """The winding number of the closed triangle surface `corners` (T, 3, 3)
    about each of `points` (P, 3): its solid angle over 4 pi (Van Oosterom and
    Strackee's formula for a triangle's solid angle)."""
    out = np.zeros(len(points))
    chunk = max(1, 500_000 // max(len(corners), 1))  # points per pass: about 100 MB of temporaries
    for begin in range(0, len(points), chunk):
        p = points[begin:begin + chunk, None, None, :]
        v = corners[None, :, :, :] - p                      # (p, T, 3, 3)
        a, b, c = v[..., 0, :], v[..., 1, :], v[..., 2, :]
        la, lb, lc = (np.linalg.norm(x, axis=-1) for x in (a, b, c))
        det = np.einsum("...i,...i", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("...i,...i", a, b) * lc + np.einsum("...i,...i", a, c) * lb
               + np.einsum("...i,...i", b, c) * la)
        out[begin:begin + chunk] = (2.0 * np.arctan2(det, den)).sum(axis=1) / (4.0 * np.pi)
    return out


def on_surface(points, corners, tolerance):
    """Whether each of `points` lies within `tolerance` of one of the triangles
    `corners` (T, 3, 3): where the winding number is 1/2, or anything between
    0 and 1 where the point lies on an edge of the fan."""
    out = np.zeros(len(points), dtype=bool)
    a, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 2] - corners[:, 0]
    normal = np.cross(e1, e2)
    area2 = np.linalg.norm(normal, axis=1)
    ok = area2 > 0
    a, e1, e2, normal, area2 = a[ok], e1[ok], e2[ok], normal[ok] / area2[ok, None], area2[ok]
    chunk = max(1, 500_000 // max(len(a), 1))
    for begin in range(0, len(points), chunk):
        d = points[begin:begin + chunk, None, :] - a[None]                      # (p, T, 3)
        height = np.einsum("ptk,tk->pt", d, normal)
        # Barycentric coordinates of the point's projection (Cramer's rule in the plane).
        u = np.einsum("ptk,tk->pt", np.cross(d, e2), normal) / area2
        v = np.einsum("ptk,tk->pt", np.cross(e1, d[:, :, :]), normal) / area2
        slack = tolerance / np.sqrt(area2)
        close = (np.abs(height) <= tolerance) & (u >= -slack) & (v >= -slack) & (u + v <= 1 + slack)
        out[begin:begin + chunk] = close.any(axis=1)
    return out


def empty_closed_faces(arrays, points):
    """Per face of the scene `arrays` (SceneBuilder.arrays()), whether it belongs
    to a closed object, wound outwards, with none of `points` (the lights'
    positions, the camera's) and no other object's vertex inside it: its
    inside (back) side can be left out."""
    positions, face_vertices, face_sizes = arrays["positions"], arrays["face_vertices"], arrays["face_sizes"]
    face_part, occludes = arrays["face_part"], arrays["occludes"]
    out = np.zeros(len(face_sizes), dtype=bool)
    if len(face_sizes) == 0:
        return out
    corner_part = np.repeat(face_part, face_sizes)
    vertex_part = np.full(len(positions), -1, dtype=np.int64)
    vertex_part[face_vertices] = corner_part
    # Every point another object could lie inside by: all vertices, then the extra points.
    probes = np.concatenate([positions, np.asarray(points, dtype=np.float64).reshape(-1, 3)])
    probe_part = np.concatenate([vertex_part, np.full(len(probes) - len(positions), -1)])
    for part in np.unique(face_part):
        faces = np.flatnonzero((face_part == part) & occludes)
        if len(faces) < 4 or len(faces) != np.count_nonzero(face_part == part):
            continue
        corners, sizes = face_vertices[corner_part == part], face_sizes[faces]  # a part's faces are consecutive
        if not is_closed(corners, sizes):
            continue
        triangles = positions[_fan_triangles(corners, sizes)]
        lo, hi = triangles.reshape(-1, 3).min(axis=0), triangles.reshape(-1, 3).max(axis=0)
        centre = 0.5 * (lo + hi)
        t = triangles - centre
        volume = np.einsum("ij,ij", t[:, 0], np.cross(t[:, 1], t[:, 2])) / 6.0
        if not volume > MIN_RELATIVE_VOLUME * np.linalg.norm(hi - lo) ** 3:
            continue  # flat, or wound inwards (a room seen from inside)
        near = np.flatnonzero((probe_part != part) & np.all((probes >= lo) & (probes <= hi), axis=1))
        if len(near) * len(triangles) > MAX_PAIRS:
            continue
        if len(near):
            # On its surface is not inside it: an object standing on it, a wall it stands against.
            near = near[~on_surface(probes[near], triangles, ON_SURFACE * np.linalg.norm(hi - lo))]
            if len(near) and (winding_numbers(probes[near], triangles) > INSIDE_WINDING).any():
                continue
        out[faces] = True
    return out
