"""Large scenes built from arrays in one go (numpy, no per-face Python), for
scaling runs: up to millions of faces in seconds.

- `dense_objects(faces, objects)`: a few dense objects, synthetic_scenes'
  large_room with `objects` lumpy spheres (icospheres subdivided to about
  faces / objects triangles each, their radius rippled by a third so each has
  dents that see one another, as a sculpted or scanned mesh has) standing on
  the floor.
- many small objects: synthetic_scenes.box_field.

Each returns a SceneBuilder (addon/model/arrays.py).
"""

import numpy as np

from synthetic_scenes import large_room


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
    b = large_room()
    for k in range(objects):
        i, j = divmod(k, side)
        at = np.array([10 + 2.5 * (i - (side - 1) / 2), 10 + 2.5 * (j - (side - 1) / 2), 0.0])
        b.add(lumpy + at, f.ravel(), np.full(len(f), 3), (0.7, 0.5, 0.3), 0.0, False)
    return b
