"""The wording of the solver's findings (addon/model/findings.py) in plain Python:
the records a real Scene gives for broken faces and a SolveReuse gives for
a solve it could not relight, worded as the panel shows them."""

import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parents[1] / "native"))  # synthetic_scenes

import _radiosity as rad  # noqa: E402
from model import findings  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box, native_scene, room_with_blocker  # noqa: E402


def broken_faces():
    """A lit room and one face of each fault, with the object each face belongs to."""
    b, parts = room_with_blocker()
    owner = {f: "Room" for f in parts["room"]}
    owner.update({parts["light"]: "Lamp", parts["blocker"][0]: "Plate"})
    faults = {
        "Dot": [(1, 1, 1), (1, 1, 1), (1, 1, 1)],                                  # coincident corners
        "Line": [(1, 1, 1), (2, 1, 1), (3, 1, 1)],                                 # collinear
        "Bow": [(1, 1, 1), (2, 2, 1), (2, 1, 1), (1, 2, 1)],                       # crosses itself
        # Too small (under 1e-7 of the scene's diameter), and yet larger than the
        # grid the solver's frame rounds positions to (2^-32 of it): not a dot.
        "Speck": [(1, 1, 2), (1 + 1e-7, 1, 2), (1, 1 + 1e-7, 2)],
        "Bent": [(1, 1, 0.5), (2, 1, 0.5), (2, 2, 0.7), (1, 2, 0.5)],              # not planar
        "Bent2": [(1, 1, 0.3), (2, 1, 0.3), (2, 2, 0.4), (1, 2, 0.3)],             # not planar
        "Twice": [(1, 3, 1), (2, 3, 1), (2, 3, 1), (2, 3.5, 1), (1, 3.5, 1)],      # a repeated corner
    }
    for name, corners in faults.items():
        owner[b.polygon(corners, reflectance=0.5)] = name.rstrip("2")
    return b, owner


class FaceNotes(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        b, cls.owner = broken_faces()
        cls.scene = b.scene(rad)
        cls.face_object = cls.owner.__getitem__

    def test_every_kind_of_note_has_words(self):
        kinds = {n["kind"] for n in self.scene.skipped_faces + self.scene.repaired_faces}
        self.assertEqual(kinds, {"coincident_corners", "collinear_corners", "crosses_itself", "too_small",
                                 "not_planar", "repeated_corners"})
        self.assertLessEqual(kinds, set(findings.FACE_ISSUES))

    def test_faces_left_out_are_named_by_object_and_reason(self):
        message = findings.face_notes_message(self.face_object, self.scene.skipped_faces, "faces left out:", most=10)
        self.assertTrue(message.startswith("faces left out: "), message)
        for part in ("Dot: 1 face zero area (coincident vertices)", "Line: 1 face zero area (collinear vertices)",
                     "Bow: 1 face its outline crosses itself"):
            self.assertIn(part, message)
        # 1.41e-07 across, give or take the grid's rounding of its corners.
        self.assertRegex(message, r"Speck: 1 face too small to solve \(1\.[34]\de-07 across\)")

    def test_repairs_give_their_numbers(self):
        message = findings.face_notes_message(self.face_object, self.scene.repaired_faces, "faces repaired:")
        bends = [100 * n["bend"] for n in self.scene.repaired_faces if n["kind"] == "not_planar"]
        self.assertEqual(len(bends), 2)
        self.assertIn("Bent: 2 faces not planar: split into 2 planar triangles (most: %.3g %%)" % max(bends), message)
        self.assertIn("Twice: 1 face repeated corners removed", message)

    def test_a_long_list_is_cut_short(self):
        message = findings.face_notes_message(self.face_object, self.scene.skipped_faces, "faces left out:", most=2)
        self.assertEqual(message.count(";"), 1, message)
        self.assertTrue(message.endswith(" and 2 more"), message)
        self.assertEqual(findings.face_notes_message(self.face_object, [], "faces left out:"), "")


class CoincidentFaces(unittest.TestCase):
    def test_objects_in_the_same_place_are_named_once_per_pair(self):
        b = SceneBuilder()
        add_box(b, (0, 0, 0), (4, 4, 3), reflectance=0.6, inward=True)
        b.polygon([(1, 1, 2.99), (1, 2, 2.99), (2, 2, 2.99), (2, 1, 2.99)], reflectance=0.0, emission=5.0, two_sided=False)
        owner = {f: "Room" for f in range(b.face_count)}
        for name in ("Card", "Copy", "Card"):
            owner[b.polygon([(1, 1, 1), (2, 1, 1), (2, 2, 1), (1, 2, 1)], reflectance=0.5)] = name
        pairs = b.scene(rad).coincident_faces
        self.assertTrue(pairs)
        self.assertEqual(findings.coincident_message(owner.__getitem__, pairs),
                         "faces in the same place, counted once: Card and Copy; Card")
        self.assertEqual(findings.coincident_message(owner.__getitem__, []), "")


class RelinkReasons(unittest.TestCase):
    def test_a_changed_scene_says_why_it_linked_anew(self):
        b, parts = room_with_blocker()
        reuse = rad.SolveReuse()
        first = rad.solve(b.scene(rad), quality=0.2, reuse=reuse)
        self.assertEqual(findings.relink_reason(first.stats["reuse_refusal"]), "")  # nothing kept: no news
        a = b.arrays()
        a["positions"][-1] += (0.0, 0.0, 0.01)  # the plate's last corner
        moved_scene = native_scene(rad, a)
        moved = rad.solve(moved_scene, quality=0.2, reuse=reuse)
        self.assertEqual(findings.relink_reason(moved.stats["reuse_refusal"]), "the geometry changed")
        relit = rad.solve(moved_scene, quality=0.2, reuse=reuse)
        self.assertTrue(relit.stats["reused"])
        self.assertEqual(findings.relink_reason(relit.stats["reuse_refusal"]), "")
        changed = rad.solve(moved_scene, quality=0.3, reuse=reuse)
        self.assertEqual(findings.relink_reason(changed.stats["reuse_refusal"]), "the quality changed")


if __name__ == "__main__":
    unittest.main()
