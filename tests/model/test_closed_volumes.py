"""Which closed objects' inside sides can be left out (addon/model/closed_volumes.py),
in plain Python."""

import unittest

import numpy as np

from model import arrays, closed_volumes

# scene_kit's box faces (normals out), corners as in box_between.
CORNERS = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
QUADS = np.array([(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)])


def add_box(builder, lo, hi, omit=(), inward=False):
    quads = np.delete(QUADS, list(omit), axis=0)
    if inward:
        quads = quads[:, ::-1]
    corners = np.asarray(lo) + CORNERS * (np.asarray(hi) - np.asarray(lo))
    return builder.add(corners, quads.ravel(), np.full(len(quads), 4), 0.5, 0.0, True)


def empty(builder, points=()):
    a = builder.arrays()
    per_face = closed_volumes.empty_closed_faces(a, np.array(points, dtype=float).reshape(-1, 3))
    return [bool(per_face[a["face_part"] == p].all()) for p in range(builder.part_count)]


class ClosedTest(unittest.TestCase):
    def test_a_box_is_closed_an_open_one_is_not(self):
        self.assertTrue(closed_volumes.is_closed(QUADS.ravel(), np.full(6, 4)))
        self.assertFalse(closed_volumes.is_closed(QUADS[1:].ravel(), np.full(5, 4)))
        # One face turned the other way: closed, but not consistently wound.
        turned = QUADS.copy()
        turned[0] = turned[0][::-1]
        self.assertFalse(closed_volumes.is_closed(turned.ravel(), np.full(6, 4)))

    def test_winding_number_inside_on_and_outside(self):
        triangles = CORNERS[closed_volumes._fan_triangles(QUADS.ravel(), np.full(6, 4))]
        w = closed_volumes.winding_numbers(np.array([[0.5, 0.5, 0.5], [0.5, 0.5, 1.0], [2.0, 0.5, 0.5]]), triangles)
        np.testing.assert_allclose(w, [1.0, 0.5, 0.0], atol=1e-12)


class EmptyInsideTest(unittest.TestCase):
    def test_a_box_in_a_room(self):
        b = arrays.SceneBuilder()
        add_box(b, (0, 0, 0), (4, 4, 3), inward=True)   # the room: wound inwards, seen from inside
        add_box(b, (1, 1, 0), (2, 2, 1))                  # a box standing on its floor
        add_box(b, (2, 2, 0), (3, 3, 1), omit=(1,))       # a box without a lid
        self.assertEqual(empty(b, [(3, 3, 2.5)]), [False, True, False])

    def test_what_lies_inside_keeps_the_inside(self):
        for inner, points in ((True, ()), (False, [(0.5, 0.5, 0.5)])):
            b = arrays.SceneBuilder()
            add_box(b, (0, 0, 0), (1, 1, 1))
            if inner:
                add_box(b, (0.4, 0.4, 0.4), (0.6, 0.6, 0.6))   # another object inside it
            self.assertEqual(empty(b, points)[0], False)
            if inner:
                self.assertEqual(empty(b, points)[1], True)     # the inner one is empty itself

    def test_a_light_just_under_a_face_is_inside(self):
        # On the fan's diagonal of the top face, a thousandth under it.
        b = arrays.SceneBuilder()
        add_box(b, (0, 0, 0), (1, 1, 1))
        self.assertEqual(empty(b, [(0.5, 0.5, 0.999)]), [False])
        self.assertEqual(empty(b, [(0.5, 0.5, 1.0)]), [True])     # on it: not inside

    def test_an_object_standing_on_a_closed_one_is_not_inside_it(self):
        b = arrays.SceneBuilder()
        add_box(b, (0, 0, 0), (1, 1, 1))
        add_box(b, (0.2, 0.2, 1), (0.8, 0.8, 1.5))
        self.assertEqual(empty(b), [True, True])

    def test_two_faces_back_to_back_are_not_a_volume(self):
        b = arrays.SceneBuilder()
        square = np.array([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)], dtype=float)
        b.add(square, [0, 1, 2, 3, 3, 2, 1, 0], [4, 4], 0.5, 0.0, True)
        self.assertEqual(empty(b), [False])

    def test_lights_are_never_closed_objects(self):
        b = arrays.SceneBuilder()
        corners = np.asarray(CORNERS)
        b.add(corners, QUADS.ravel(), np.full(6, 4), 0.0, 1.0, False, occludes=False)
        self.assertEqual(empty(b), [False])


if __name__ == "__main__":
    unittest.main()
