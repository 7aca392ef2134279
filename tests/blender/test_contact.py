"""Agreement with Cycles where surfaces touch or nearly touch (issue 12's acceptance).

Scenes built the way users build them, Lambertian (Diffuse BSDF) materials:
the Cornell box as published (its light 0.1 mm under the ceiling), the same
with the light 1 mm and 1 cm under it, a box standing on a floor under an area
light, an emissive plane lying on a table top, a picture 1 mm in front of a
wall. For each oracle at qualities 0.3, 0.5 and 0.8, solved at the default
settings otherwise, the baked solution rendered from the scene's camera must
match a path trace of the original scene: mean linear luminance within 3 %
(signed "exposure" error) and the median 8 x 8-pixel-block relative error
within 6 %, emitter pixels left out (image_agreement.py and
render_compare.emitter_mask say how).

The path-traced reference (128 x 128 pixels, seeds of 128 samples added in
pairs until its noise is below a sixth of the block tolerance and a tenth of
the exposure one) is cached under <build>/contact_cache, so only the first run
renders it; its noise, measured from its seeds, must be below a quarter of
the tolerances (measured on this machine: median block noise 0.2-1.0 %,
exposure noise below 0.1 %).
Each (scene, oracle, quality) is solved once and rendered with 8 samples (the
solution is noise-free). Every case prints "[agreement]" lines (run_tests -v):
the reference's noise, then per oracle and quality the signed exposure error
and the median block error. Renders (reference, emitter mask in magenta, every
solution) are written to $RADIOSITY_TEST_IMAGES if set.
"""

import unittest

import contact_agreement as ca


class ContactAgreementTest(unittest.TestCase):
    def agree(self, label):
        ca.assert_agreement(self, label)

    def test_cornell_box_as_published(self):
        self.agree("cornell_box")

    def test_cornell_box_light_1mm_under_ceiling(self):
        self.agree("cornell_box_1mm")

    def test_cornell_box_light_1cm_under_ceiling(self):
        self.agree("cornell_box_1cm")

    def test_box_standing_on_floor(self):
        self.agree("box_on_floor")

    def test_emissive_plane_on_table_top(self):
        self.agree("lamp_on_table")

    def test_picture_1mm_in_front_of_wall(self):
        self.agree("picture_on_wall")


if __name__ == "__main__":
    unittest.main()
