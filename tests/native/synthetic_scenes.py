"""Small scenes built from arrays, for testing the native solver without
Blender: the add-on's SceneBuilder (addon/model/arrays.py, its parts given as
polygons and boxes here) and scene_kit's boxes (scenes/scene_kit.py)."""

import pathlib
import sys

import numpy as np

ROOT = pathlib.Path(__file__).resolve().parents[2]
# The add-on's model as built (run_tests.py puts build/addon/radiosity first on
# sys.path) or, for bench/ run without it, as in the source.
sys.path.append(str(ROOT / "addon"))
sys.path.append(str(ROOT / "scenes"))

from model.arrays import SceneBuilder, native_scene  # noqa: E402,F401  (SceneBuilder: for the tests)
from scene_kit import box_between  # noqa: E402


def add_box(b, lo, hi, reflectance=0.5, emission=0.0, inward=False, omit=(), two_sided=True):
    """The quads of the axis-aligned box from lo to hi (scene_kit.box_between)
    added to builder `b`, facing out (or in, for a room); reflectance, emission and
    two_sided for all of them or one per face. Returns their face indices."""
    first = b.face_count
    vertices, quads = box_between(lo, hi, omit, inward)
    b.add(vertices, quads.ravel(), np.full(len(quads), 4), reflectance, emission, two_sided)
    return list(range(first, b.face_count))


def scaled_scene(rad, b, scale=1.0, emission_scale=1.0):
    """The Scene of builder `b` with its positions and emission scaled."""
    a = b.arrays()
    a["positions"] = a["positions"] * scale
    a["emission"] = a["emission"] * emission_scale
    return native_scene(rad, a)


def room_with_blocker(light=5.0, gap=0.01):
    """A 4 x 4 x 3 room, a square ceiling light facing down `gap` under the
    ceiling, and a floating 1.2 m square plate at 1 m under it: umbra,
    penumbra and lit floor."""
    b = SceneBuilder()
    room = add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.6, inward=True)
    z = 3.0 - gap
    light_face = b.polygon([(1.7, 1.7, z), (1.7, 2.3, z), (2.3, 2.3, z), (2.3, 1.7, z)],
                           0.0, emission=light, two_sided=False)
    plate = b.polygon([(1.4, 1.4, 1.0), (2.6, 1.4, 1.0), (2.6, 2.6, 1.0), (1.4, 2.6, 1.0)], 0.5)
    return b, dict(room=room, light=light_face, blocker=[plate])


def large_room():
    """A 20 x 20 x 4 m room and a 2 m square light 1 cm under its ceiling, facing
    down (emission 10): the room of the scaling scenes (box_field,
    large_scenes.dense_objects)."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (20, 20, 4), reflectance=0.6, inward=True)
    b.polygon([(9, 9, 3.99), (9, 11, 3.99), (11, 11, 3.99), (11, 9, 3.99)], 0.0, emission=10.0, two_sided=False)
    return b


def box_field(faces):
    """A 20 x 20 x 4 room with a ceiling light and a grid of open boxes (5
    two-sided faces each; the bottom touches the floor and is never seen) on
    its floor: about `faces` input faces, for scaling runs. Built in one go
    (numpy, no per-box Python): up to millions of faces in seconds."""
    b = large_room()
    count = max(1, (faces - 7) // 5)
    side = int(np.ceil(np.sqrt(count)))
    pitch = 18.0 / side
    i, j = np.divmod(np.arange(count), side)
    origin = np.stack([1 + i * pitch, 1 + j * pitch, np.zeros(count)], axis=1)
    unit, quads = box_between((0, 0, 0), (1, 1, 1), omit=("bottom",))
    positions = (origin[:, None, :] + (0.5 * pitch) * unit[None]).reshape(-1, 3)
    face_vertices = (quads[None] + len(unit) * np.arange(count)[:, None, None]).ravel()
    b.add(positions, face_vertices, np.full(len(quads) * count, 4), 0.5, 0.0, True)
    return b
