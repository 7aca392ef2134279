"""Array logic of the scene export and the bake, free of `bpy`.

Everything here takes and returns numpy arrays, so it can be tested in plain
Python (tests/model/test_arrays.py) and stays fast: no per-vertex Python
loops. export.py reads Blender data into these functions, bake.py writes
their results back.
"""

import math

import numpy as np

# Power-to-radiance of a Blender area light, L = factor * P / A (A the area with
# object scale, pi d^2 / 4 for disks), measured in Cycles, not recalled: a white
# Diffuse BSDF plane 1 m under the light, direct light only, against an emissive
# polygon of the same shape (tests/blender/test_light_conversion.py, which runs in
# every tested Blender and records the numbers). Blender 3.4.1: L A / P = 0.2500
# for squares and scaled rectangles, 0.2504 for a disk: 1/4. Blender 4.5.15 and
# 5.0.1: 0.3183, disk 0.3188: 1/pi. Cycles changed it in 4.0 (DESIGN.md section
# 3; 4.0 to 4.4 are not measured here). Since 4.x a light's exposure e multiplies
# L by 2^e, and with `normalize` off L = factor * P, not divided by the area
# (both measured in 4.5 and 5.0).
AREA_LIGHT_FACTOR_BEFORE_4 = 0.25
AREA_LIGHT_FACTOR_4 = 1.0 / math.pi

# Polygon sides of a disk or ellipse light. The polygon's radius is enlarged so
# that its area equals the ideal shape's, so it emits the same power.
ROUND_LIGHT_SIDES = 16


def area_light_factor(blender_version):
    """L = factor * P / A for Blender `blender_version` (a tuple like (3, 4, 1))."""
    return AREA_LIGHT_FACTOR_BEFORE_4 if tuple(blender_version) < (4, 0, 0) else AREA_LIGHT_FACTOR_4


def area_light_radiance(blender_version, power, area, colour, exposure=0.0, normalize=True):
    """Radiance (rgb) of an area light of `power` W and world `area` (m^2) in Blender
    `blender_version`; `exposure` (stops) and `normalize` as the light's (4.x)."""
    radiance = area_light_factor(blender_version) * power * 2.0 ** exposure
    if normalize:
        radiance /= area
    return radiance * np.asarray(colour, dtype=float)


def area_light_polygon(shape, size_x, size_y, sides=ROUND_LIGHT_SIDES):
    """(vertices (n, 3), ideal area) of an area light in its local frame.

    The light lies in z = 0 and emits along -z, so the polygon is wound
    clockwise seen from +z: its normal (right-hand rule) is -z.
    `shape` is Blender's: 'SQUARE' and 'DISK' use size_x for both axes.
    """
    if shape in ('SQUARE', 'DISK'):
        size_y = size_x
    hx, hy = 0.5 * size_x, 0.5 * size_y
    if shape in ('SQUARE', 'RECTANGLE'):
        xy = np.array([[-hx, -hy], [-hx, hy], [hx, hy], [hx, -hy]])
        area = size_x * size_y
    elif shape in ('DISK', 'ELLIPSE'):
        area = math.pi * hx * hy
        # A regular n-gon inscribed in the unit circle has area n/2 sin(2 pi / n).
        grow = math.sqrt(math.pi / (0.5 * sides * math.sin(2.0 * math.pi / sides)))
        angles = -np.arange(sides) * (2.0 * math.pi / sides)  # clockwise
        xy = np.stack([hx * grow * np.cos(angles), hy * grow * np.sin(angles)], axis=1)
    else:
        raise ValueError("unknown area light shape %r" % (shape,))
    return np.column_stack([xy, np.zeros(len(xy))]), area


def scaled_area(matrix, local_area):
    """Area in world space of a local-xy-plane shape of `local_area` under `matrix` (4x4)."""
    m = np.asarray(matrix, dtype=float)
    return local_area * float(np.linalg.norm(np.cross(m[:3, 0], m[:3, 1])))


def transform_points(points, matrix):
    """Points (n, 3) through the affine 4x4 `matrix`."""
    m = np.asarray(matrix, dtype=float)
    return np.asarray(points, dtype=float) @ m[:3, :3].T + m[:3, 3]


def polygon_corners(loop_start, loop_total, loop_vertex):
    """Vertex indices of every polygon's corners, concatenated in polygon order.

    Blender stores corners (loops) per polygon from loop_start, usually but not
    necessarily contiguous and in polygon order; this gathers them in order.
    """
    loop_start = np.asarray(loop_start, dtype=np.int64)
    loop_total = np.asarray(loop_total, dtype=np.int64)
    offsets = np.cumsum(loop_total) - loop_total
    k = np.arange(int(loop_total.sum()), dtype=np.int64) - np.repeat(offsets, loop_total)
    return np.asarray(loop_vertex, dtype=np.int64)[np.repeat(loop_start, loop_total) + k]


def reverse_polygons(face_vertices, face_sizes):
    """Every polygon's corners in reverse order (flips its normal)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    starts = np.cumsum(face_sizes) - face_sizes
    k = np.arange(int(face_sizes.sum()), dtype=np.int64) - np.repeat(starts, face_sizes)
    return np.asarray(face_vertices)[np.repeat(starts + face_sizes - 1, face_sizes) - k]


# Blender stores an Inf typed into a property as the largest float: as good as Inf.
FLOAT_MAX = float(np.finfo(np.float32).max)


def finite(values):
    """True where finite and below FLOAT_MAX in magnitude (NaN compares False)."""
    return np.abs(np.asarray(values, dtype=np.float64)) < FLOAT_MAX


def finite_faces(positions, face_vertices, face_sizes):
    """(F,) True where every corner of the face has finite coordinates (`finite`)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    corner_ok = finite(np.asarray(positions, dtype=np.float64)[face_vertices]).all(axis=1)
    bad = np.zeros(len(face_sizes), dtype=bool)
    bad[np.repeat(np.arange(len(face_sizes)), face_sizes)[~corner_ok]] = True
    return ~bad


def keep_faces(positions, face_vertices, face_sizes, keep):
    """Only the faces where `keep`, with only the vertices they use:
    (positions, face_vertices, face_sizes, corner mask of the input corners)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    corner_keep = np.repeat(np.asarray(keep, dtype=bool), face_sizes)
    used, local = np.unique(np.asarray(face_vertices, dtype=np.int64)[corner_keep], return_inverse=True)
    return np.asarray(positions)[used], local.reshape(-1), face_sizes[keep], corner_keep


def srgb_to_linear(c):
    """sRGB-encoded values in [0, 1] to linear (the standard piecewise curve)."""
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


class SceneBuilder:
    """Concatenates parts (one per object instance or light) into the solver's arrays.

    Each part gets an index; `face_part` says which part every face came from,
    so the solved polygons can be sent back to their objects.
    """

    def __init__(self):
        self._positions, self._face_vertices, self._face_sizes = [], [], []
        self._reflectance, self._emission, self._two_sided, self._face_part = [], [], [], []
        self._occludes = []
        self._vertex_count = 0
        self.part_count = 0

    def add(self, positions, face_vertices, face_sizes, reflectance, emission, two_sided, occludes=True):
        """Add a part; per-face arrays have one row per face. Returns the part index.

        `occludes` False: the part emits but casts no shadow (a Blender light:
        Cycles lets light through it)."""
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        face_sizes = np.asarray(face_sizes, dtype=np.int64)
        faces = len(face_sizes)
        part = self.part_count
        self._positions.append(positions)
        self._face_vertices.append(np.asarray(face_vertices, dtype=np.int64) + self._vertex_count)
        self._face_sizes.append(face_sizes)
        self._reflectance.append(np.broadcast_to(np.asarray(reflectance, dtype=np.float64), (faces, 3)))
        self._emission.append(np.broadcast_to(np.asarray(emission, dtype=np.float64), (faces, 3)))
        self._two_sided.append(np.broadcast_to(np.asarray(two_sided, dtype=bool), (faces,)))
        self._occludes.append(np.broadcast_to(np.asarray(occludes, dtype=bool), (faces,)))
        self._face_part.append(np.full(faces, part, dtype=np.int64))
        self._vertex_count += len(positions)
        self.part_count += 1
        return part

    def polygon(self, corners, reflectance=0.5, emission=0.0, two_sided=True, occludes=True):
        """Add one face, its own part, from its corners (n, 3). Returns the face's index."""
        face = self.face_count
        self.add(corners, np.arange(len(corners)), [len(corners)], reflectance, emission, two_sided, occludes)
        return face

    @property
    def face_count(self):
        return sum(len(s) for s in self._face_sizes)

    def arrays(self):
        """dict of the solver's Scene arguments plus 'face_part'."""
        def cat(parts, shape, dtype):
            return np.concatenate(parts).astype(dtype) if parts else np.empty(shape, dtype)

        return {
            "positions": cat(self._positions, (0, 3), np.float64),
            "face_vertices": cat(self._face_vertices, (0,), np.int64),
            "face_sizes": cat(self._face_sizes, (0,), np.int64),
            "reflectance": np.clip(cat(self._reflectance, (0, 3), np.float64), 0.0, 1.0),
            "emission": np.maximum(cat(self._emission, (0, 3), np.float64), 0.0),
            "two_sided": cat(self._two_sided, (0,), bool),
            "occludes": cat(self._occludes, (0,), bool),
            "face_part": cat(self._face_part, (0,), np.int64),
        }

    def scene(self, solver, lights=None, world=None):
        """The solver's Scene of the parts added (native_scene)."""
        return native_scene(solver, self.arrays(), lights, world)


def native_scene(solver, scene_arrays, lights=None, world=None):
    """`solver.Scene` (the native module's) of SceneBuilder.arrays()' dict, with
    the lights and the world's colour; ValueError where the solver refuses them."""
    a = scene_arrays
    return solver.Scene(a["positions"], a["face_vertices"], a["face_sizes"], a["reflectance"], a["emission"],
                        a["two_sided"], occludes=a["occludes"], lights=lights, world=world)


def polygon_normals(positions, face_vertices, face_sizes):
    """Unit normals (Newell's method, any polygon size) of polygons, (P, 3)."""
    positions = np.asarray(positions, dtype=np.float64)
    face_vertices = np.asarray(face_vertices, dtype=np.int64)
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    starts = np.cumsum(face_sizes) - face_sizes
    k = np.arange(len(face_vertices), dtype=np.int64) - np.repeat(starts, face_sizes)
    # The next corner of every corner, wrapping around its polygon.
    nxt = np.repeat(starts, face_sizes) + (k + 1) % np.repeat(face_sizes, face_sizes)
    a, b = positions[face_vertices], positions[face_vertices[nxt]]
    terms = np.cross(a, b)
    normals = np.zeros((len(face_sizes), 3))
    np.add.at(normals, np.repeat(np.arange(len(face_sizes)), face_sizes), terms)
    length = np.linalg.norm(normals, axis=1, keepdims=True)
    return normals / np.maximum(length, 1e-300)


def offset_sides(positions, face_vertices, face_sizes, distance):
    """Positions moved `distance` along the normal of the polygons using them.

    The two sides of a two-sided face come out as coincident polygons facing
    away from each other; moving each a little towards the side it shows keeps
    a renderer from confusing them (both are hit at the same distance).
    A vertex used by polygons of different normals gets their mean direction.
    """
    positions = np.asarray(positions, dtype=np.float64)
    normals = polygon_normals(positions, face_vertices, face_sizes)
    per_vertex = np.zeros_like(positions)
    np.add.at(per_vertex, np.asarray(face_vertices, dtype=np.int64),
              np.repeat(normals, np.asarray(face_sizes, dtype=np.int64), axis=0))
    length = np.linalg.norm(per_vertex, axis=1, keepdims=True)
    per_vertex = np.divide(per_vertex, length, out=np.zeros_like(per_vertex), where=length > 0)
    return positions + distance * per_vertex


def split_result(face_vertices, face_sizes, polygon_part, part_count):
    """Split the solved mesh by part.

    Returns a list (one entry per part, None for parts without polygons) of
    (polygons, vertices, local_face_vertices): the indices of the part's
    polygons in the result, the result vertices it uses (sorted), and its
    polygons' corners renumbered into those vertices.
    """
    face_vertices = np.asarray(face_vertices, dtype=np.int64)
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    polygon_part = np.asarray(polygon_part, dtype=np.int64)
    corner_part = np.repeat(polygon_part, face_sizes)
    out = []
    for part in range(part_count):
        polygons = np.flatnonzero(polygon_part == part)
        if len(polygons) == 0:
            out.append(None)
            continue
        corners = face_vertices[corner_part == part]
        vertices, local = np.unique(corners, return_inverse=True)
        out.append((polygons, vertices, local.astype(np.int64)))
    return out


def corner_values(face_points, face_sizes, face_ids, result_points, result_face_vertices,
                  result_face_sizes, result_source_face, result_source_side, result_values,
                  tolerance):
    """Values of the solution at the corners of the input faces, without refinement.

    face_points (C, 3): the world positions of the input faces' corners
    (concatenated, `face_sizes` per face, global face ids `face_ids`). Every
    input corner is also a corner of the refined elements of its face, so its
    value is the result vertex of that face at the same position (within
    `tolerance`). Of a face's two sides the brighter one (mean value) is used.
    Corners with no match take their face's mean value.
    """
    face_sizes = np.asarray(face_sizes, dtype=np.int64)
    face_ids = np.asarray(face_ids, dtype=np.int64)
    result_face_sizes = np.asarray(result_face_sizes, dtype=np.int64)
    values = np.asarray(result_values, dtype=np.float64)
    channels = values.shape[1]
    # Per result corner: its face, side, vertex.
    rc_face = np.repeat(np.asarray(result_source_face, dtype=np.int64), result_face_sizes)
    rc_side = np.repeat(np.asarray(result_source_side, dtype=np.int64), result_face_sizes)
    rc_vertex = np.asarray(result_face_vertices, dtype=np.int64)
    # Brighter side per face: mean of the corner values of each (face, side).
    face_count = int(max(face_ids.max(initial=-1), rc_face.max(initial=-1))) + 1
    brightness = values.mean(axis=1)[rc_vertex]
    sums = np.zeros((face_count, 2))
    counts = np.zeros((face_count, 2))
    np.add.at(sums, (rc_face, rc_side), brightness)
    np.add.at(counts, (rc_face, rc_side), 1.0)
    means = np.divide(sums, counts, out=np.full_like(sums, -1.0), where=counts > 0)
    best_side = np.argmax(means, axis=1)
    keep = rc_side == best_side[rc_face]
    rc_face, rc_vertex = rc_face[keep], rc_vertex[keep]
    # Mean value per face on its chosen side: the fallback.
    face_mean = np.zeros((face_count, channels))
    face_n = np.zeros(face_count)
    np.add.at(face_mean, rc_face, values[rc_vertex])
    np.add.at(face_n, rc_face, 1.0)
    face_mean /= np.maximum(face_n, 1.0)[:, None]

    # Match (face, quantised position) keys of input corners against result corners.
    corner_face = np.repeat(face_ids, face_sizes)
    q_in = np.round(np.asarray(face_points, dtype=np.float64) / tolerance).astype(np.int64)
    q_out = np.round(np.asarray(result_points, dtype=np.float64)[rc_vertex] / tolerance).astype(np.int64)
    keys_in = np.column_stack([corner_face, q_in])
    keys_out = np.column_stack([rc_face, q_out])
    all_keys = np.concatenate([keys_out, keys_in])
    _, inverse = np.unique(all_keys, axis=0, return_inverse=True)
    inverse = inverse.reshape(-1)
    ids_out, ids_in = inverse[:len(keys_out)], inverse[len(keys_out):]
    table = np.full(int(inverse.max(initial=-1)) + 1, -1, dtype=np.int64)
    table[ids_out] = rc_vertex
    matched = table[ids_in]
    result = face_mean[corner_face].copy()
    ok = matched >= 0
    result[ok] = values[matched[ok]]
    return result, int(np.count_nonzero(~ok))
