"""Large scenes built from arrays in one go (numpy, no per-face Python), for
the scale benchmark (bench/scale_bench.py) and the scale tests: up to millions
of faces in seconds.

- `box_field(faces)`: many small objects, a 20 x 20 x 4 m room with a ceiling
  light and a grid of open boxes (five two-sided faces each) on its floor, as
  synthetic_scenes.box_field builds it face by face.
- `dense_objects(faces, objects)`: a few dense ones, the same room with
  `objects` lumpy spheres (icospheres subdivided to about faces / objects
  triangles each, their radius rippled by a third so each has dents that see
  one another, as a sculpted or scanned mesh has) standing on the floor.

Each returns a `LargeScene` with the arrays of `_radiosity.Scene`.
"""

import numpy as np

ROOM = np.array([20.0, 20.0, 4.0])
LIGHT = (9.0, 11.0, 3.99)  # a 2 m square ceiling light, 1 cm under the ceiling, emission 10


class LargeScene:
    def __init__(self, positions, faces, sizes, reflectance, emission, two_sided):
        self.positions = np.ascontiguousarray(positions, float)
        self.face_vertices = np.ascontiguousarray(faces, np.int64)
        self.face_sizes = np.ascontiguousarray(sizes, np.int64)
        self.reflectance = np.ascontiguousarray(reflectance, float)
        self.emission = np.ascontiguousarray(emission, float)
        self.two_sided = np.ascontiguousarray(two_sided, bool)

    @property
    def faces(self):
        return self.face_sizes

    def scene(self, rad):
        return rad.Scene(self.positions, self.face_vertices, self.face_sizes, self.reflectance,
                         self.emission, self.two_sided)


def _join(parts):
    """Concatenates (positions, quads-or-triangles as an (n, k) array, rho, emission, two_sided) parts."""
    positions, faces, sizes, rho, emission, two = [], [], [], [], [], []
    base = 0
    for p, f, r, e, t in parts:
        positions.append(p)
        faces.append((f + base).ravel())
        sizes.append(np.full(len(f), f.shape[1]))
        rho.append(np.broadcast_to(r, (len(f), 3)))
        emission.append(np.broadcast_to(e, (len(f), 3)))
        two.append(np.full(len(f), t))
        base += len(p)
    return LargeScene(np.concatenate(positions), np.concatenate(faces), np.concatenate(sizes),
                      np.concatenate(rho), np.concatenate(emission), np.concatenate(two))


def _room():
    """The room's six walls facing in, and the light facing down."""
    x, y, z = ROOM
    corners = np.array([[0, 0, 0], [x, 0, 0], [x, y, 0], [0, y, 0],
                        [0, 0, z], [x, 0, z], [x, y, z], [0, y, z]], float)
    walls = np.array([[0, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [0, 4, 7, 3], [1, 2, 6, 5]])
    a, b, h = LIGHT
    light = np.array([[a, a, h], [a, b, h], [b, b, h], [b, a, h]])
    return [(corners, walls, 0.6, 0.0, False), (light, np.array([[0, 1, 2, 3]]), 0.0, 10.0, False)]


# The unit box's corners (index x + 2y + 4z) and its faces but the bottom, outward.
_CORNERS = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], float)
_OPEN_BOX = np.array([[4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]])


def box_field(faces):
    """About `faces` faces: the room and (faces - 7) / 5 open boxes on its floor."""
    count = max(1, (faces - 7) // 5)
    side = int(np.ceil(np.sqrt(count)))
    pitch = 18.0 / side
    i, j = np.divmod(np.arange(count), side)
    origin = np.stack([1 + i * pitch, 1 + j * pitch, np.zeros(count)], axis=1)
    size = 0.5 * pitch
    positions = (origin[:, None, :] + size * _CORNERS[None]).reshape(-1, 3)
    quads = (_OPEN_BOX[None] + 8 * np.arange(count)[:, None, None]).reshape(-1, 4)
    return _join(_room() + [(positions, quads, 0.5, 0.0, True)])


def _icosphere(subdivisions):
    """Unit icosphere: (vertices, triangles), 20 x 4^subdivisions faces, outward."""
    t = (1 + 5 ** 0.5) / 2
    v = np.array([[-1, t, 0], [1, t, 0], [-1, -t, 0], [1, -t, 0], [0, -1, t], [0, 1, t],
                  [0, -1, -t], [0, 1, -t], [t, 0, -1], [t, 0, 1], [-t, 0, -1], [-t, 0, 1]], float)
    f = np.array([[0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11], [1, 5, 9], [5, 11, 4],
                  [11, 10, 2], [10, 7, 6], [7, 1, 8], [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8],
                  [3, 8, 9], [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1]])
    v /= np.linalg.norm(v, axis=1, keepdims=True)
    for _ in range(subdivisions):
        edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
        unique, inverse = np.unique(edges, axis=0, return_inverse=True)
        inverse = inverse.ravel()
        mid = v[unique].mean(axis=1)
        mid /= np.linalg.norm(mid, axis=1, keepdims=True)
        m = len(v) + inverse.reshape(3, -1).T  # midpoints of edges 01, 12, 20 of each face
        v = np.concatenate([v, mid])
        a, b, c = f.T
        f = np.concatenate([np.stack([a, m[:, 0], m[:, 2]], 1), np.stack([b, m[:, 1], m[:, 0]], 1),
                            np.stack([c, m[:, 2], m[:, 1]], 1), m])
    return v, f


def dense_objects(faces, objects=4):
    """About `faces` faces in `objects` lumpy spheres of 1 m on the room's floor."""
    per = max(20, faces // objects)
    subdivisions = max(0, int(round(np.log(per / 20) / np.log(4))))
    v, f = _icosphere(subdivisions)
    # Ripples of a third of the radius: dents and bumps that face each other.
    ripple = 1 + 0.3 * np.sin(5 * v[:, 0]) * np.sin(5 * v[:, 1]) * np.sin(5 * v[:, 2] + 1)
    lumpy = v * ripple[:, None] * 0.5
    lumpy[:, 2] -= lumpy[:, 2].min()  # resting on the floor
    side = int(np.ceil(np.sqrt(objects)))
    parts = _room()
    for k in range(objects):
        i, j = divmod(k, side)
        at = np.array([10 + 2.5 * (i - (side - 1) / 2), 10 + 2.5 * (j - (side - 1) / 2), 0.0])
        parts.append((lumpy + at, f, (0.7, 0.5, 0.3), 0.0, False))
    return _join(parts)
