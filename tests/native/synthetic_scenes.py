"""Small scenes built from arrays, for testing the native solver without Blender."""

import numpy as np


class SceneBuilder:
    """Collects quads and triangles with their materials."""

    def __init__(self):
        self.positions, self.faces, self.reflectance, self.emission, self.two_sided = [], [], [], [], []

    def polygon(self, corners, rho=(0.5, 0.5, 0.5), emission=(0, 0, 0), two_sided=True):
        start = len(self.positions)
        self.positions.extend(np.asarray(c, float) for c in corners)
        self.faces.append(list(range(start, start + len(corners))))
        self.reflectance.append(np.broadcast_to(rho, 3))
        self.emission.append(np.broadcast_to(emission, 3))
        self.two_sided.append(two_sided)
        return len(self.faces) - 1

    def box(self, lo, hi, rho=(0.5, 0.5, 0.5), emission=(0, 0, 0), inward=False, skip=()):
        """Six quads of an axis-aligned box, facing out (or in, for a room);
        `skip` leaves out sides by index (0 bottom, 1 top, 2 -y, 3 +y, 4 -x, 5 +x)."""
        x0, y0, z0 = lo
        x1, y1, z1 = hi
        quads = [
            [(x0, y0, z0), (x0, y1, z0), (x1, y1, z0), (x1, y0, z0)],  # bottom, -z
            [(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)],  # top, +z
            [(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)],  # -y
            [(x0, y1, z0), (x0, y1, z1), (x1, y1, z1), (x1, y1, z0)],  # +y
            [(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)],  # -x
            [(x1, y0, z0), (x1, y1, z0), (x1, y1, z1), (x1, y0, z1)],  # +x
        ]
        faces = []
        for k, q in enumerate(quads):
            if k not in skip:
                faces.append(self.polygon(q[::-1] if inward else q, rho, emission))
        return faces

    def arrays(self):
        return dict(
            positions=np.array(self.positions, float),
            face_vertices=np.array([i for f in self.faces for i in f], np.int64),
            face_sizes=np.array([len(f) for f in self.faces], np.int64),
            reflectance=np.array(self.reflectance, float),
            emission=np.array(self.emission, float),
            two_sided=np.array(self.two_sided, bool),
        )

    def scene(self, rad, scale=1.0, emission_scale=1.0):
        a = self.arrays()
        return rad.Scene(a["positions"] * scale, a["face_vertices"], a["face_sizes"], a["reflectance"],
                         a["emission"] * emission_scale, a["two_sided"])


def room_with_blocker(light=5.0, gap=0.01):
    """A 4 x 4 x 3 room, a square ceiling light facing down `gap` under the
    ceiling, and a floating 1.2 m square plate at 1 m under it: umbra,
    penumbra and lit floor."""
    b = SceneBuilder()
    room = b.box((0, 0, 0), (4, 4, 3), rho=0.6, inward=True)
    z = 3.0 - gap
    light_face = b.polygon([(1.7, 1.7, z), (1.7, 2.3, z), (2.3, 2.3, z), (2.3, 1.7, z)],
                           rho=0.0, emission=light, two_sided=False)
    plate = b.polygon([(1.4, 1.4, 1.0), (2.6, 1.4, 1.0), (2.6, 2.6, 1.0), (1.4, 2.6, 1.0)], rho=0.5)
    return b, dict(room=room, light=light_face, blocker=[plate])


def box_field(faces):
    """A 20 x 20 x 4 room with a light and a grid of open boxes (5 two-sided
    faces each) on the floor: about `faces` input faces, for scaling runs."""
    b = SceneBuilder()
    b.box((0, 0, 0), (20, 20, 4), rho=0.6, inward=True)
    b.polygon([(9, 9, 3.99), (9, 11, 3.99), (11, 11, 3.99), (11, 9, 3.99)], rho=0.0, emission=10.0,
              two_sided=False)
    count = max(1, (faces - 7) // 5)
    side = int(np.ceil(np.sqrt(count)))
    pitch = 18.0 / side
    made = 0
    for i in range(side):
        for j in range(side):
            if made < count:
                x, y = 1 + i * pitch, 1 + j * pitch
                # The bottom touches the floor and is never seen: left out.
                b.box((x, y, 0), (x + 0.5 * pitch, y + 0.5 * pitch, 0.5 * pitch), rho=0.5, skip=(0,))
                made += 1
    return b
