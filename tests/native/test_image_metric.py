"""The image-quality measure of Section 6.2.3 (eq. 24) in `_image_metric` (the study-only module): brightness,
centre-surround (difference of Gaussians) filter, RMS difference, file I/O via
OpenImageIO, and its input checks.
"""

import math
import os
import tempfile
import unittest

import numpy as np

import _image_metric as metric


def phi(x):
    return 0.5 * (1.0 + math.erf(x / math.sqrt(2.0)))


class FilterTest(unittest.TestCase):
    def test_constant_image_has_no_edges(self):
        # Borders are extended, so the frame of the image is no edge either.
        f = metric.dog_filter(np.full((30, 50), 0.37))
        self.assertLess(np.abs(f).max(), 1e-12)

    def test_blur_keeps_the_mean_of_a_constant(self):
        np.testing.assert_allclose(metric.gaussian_blur(np.full((9, 11), 2.5), 1.7), 2.5, rtol=1e-12)

    def test_step_edge_gives_the_analytic_response(self):
        # A vertical step of height h between columns 29 and 30: the continuous
        # response at a pixel centre x is h (Phi(d/sc) - Phi(d/ss)), d = x - 30.
        h, sc, ss = 0.8, 3.0, 4.8
        g = np.zeros((40, 64))
        g[:, 30:] = h
        f = metric.dog_filter(g, sc, ss)
        expected = np.array([h * (phi((i + 0.5 - 30) / sc) - phi((i + 0.5 - 30) / ss)) for i in range(64)])
        np.testing.assert_allclose(f[20], expected, atol=2e-3 * h)
        # Odd about the edge, largest just beside it, nothing far away.
        np.testing.assert_allclose(f[20, 30:40], -f[20, 29:19:-1], atol=1e-12)
        self.assertLess(abs(f[20, 0]), 1e-6)
        self.assertGreater(f[20, 30:].max(), 0.1 * h)

    def test_default_sigmas_scale_with_width(self):
        c640, s640 = metric.edge_filter_sigmas(640)
        c320, s320 = metric.edge_filter_sigmas(320)
        self.assertAlmostEqual(c640, 2 * c320)
        self.assertGreater(s640, c640)
        self.assertAlmostEqual(s640 / c640, s320 / c320)

    def test_bad_sigmas_raise(self):
        g = np.zeros((8, 8))
        with self.assertRaisesRegex(ValueError, "sigma_surround must exceed"):
            metric.dog_filter(g, 2.0, 1.0)
        with self.assertRaisesRegex(ValueError, "sigma must be positive"):
            metric.gaussian_blur(g, 0.0)


class RmsTest(unittest.TestCase):
    def test_identical_images_have_zero_error(self):
        a = np.random.default_rng(1).random((20, 30))
        self.assertEqual(metric.rms_difference(a, a), 0.0)

    def test_known_difference(self):
        a = np.zeros((4, 5))
        b = np.zeros((4, 5))
        b[0, :] = 2.0   # 5 of 20 pixels off by 2: sqrt(5 * 4 / 20) = 1
        self.assertAlmostEqual(metric.rms_difference(a, b), 1.0)

    def test_scaling_both_images_scales_the_error_linearly(self):
        rng = np.random.default_rng(2)
        a, b = rng.random((24, 32)), rng.random((24, 32))
        e = metric.rms_difference(metric.dog_filter(a), metric.dog_filter(b))
        e3 = metric.rms_difference(metric.dog_filter(3 * a), metric.dog_filter(3 * b))
        self.assertGreater(e, 0.0)
        self.assertAlmostEqual(e3, 3 * e, places=12)

    def test_size_mismatch_raises(self):
        with self.assertRaisesRegex(ValueError, "differ in size"):
            metric.rms_difference(np.zeros((4, 5)), np.zeros((5, 4)))


class BrightnessTest(unittest.TestCase):
    def test_linear_is_rec709_luminance(self):
        img = np.array([[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 2.0]]], dtype=np.float32)
        np.testing.assert_allclose(metric.brightness(img, "linear"), [[0.2126, 0.7152, 0.1444]], rtol=1e-6)

    def test_display_clips_and_encodes(self):
        img = np.array([[[0.0] * 3, [0.18] * 3, [1.0] * 3, [30.0] * 3]], dtype=np.float32)
        b = metric.brightness(img, "display")[0]
        self.assertAlmostEqual(b[0], 0.0)
        self.assertAlmostEqual(b[1], 1.055 * 0.18 ** (1 / 2.4) - 0.055, places=6)   # mid grey ~0.46
        self.assertAlmostEqual(b[2], 1.0, places=6)
        self.assertAlmostEqual(b[3], 1.0, places=6)   # an emitter is as white as the display goes

    def test_unknown_encoding_raises(self):
        with self.assertRaisesRegex(ValueError, "encoding"):
            metric.brightness(np.zeros((2, 2, 3)), "gamma")


class FileTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        self.addCleanup(self.tmp.cleanup)

    def path(self, name):
        return os.path.join(self.tmp.name, name)

    def test_exr_round_trip_is_exact(self):
        img = np.random.default_rng(3).random((12, 17, 3)).astype(np.float32) * 5
        metric.write_image(self.path("a.exr"), img)
        np.testing.assert_array_equal(metric.read_image(self.path("a.exr")), img)

    def test_image_errors_matches_the_array_functions(self):
        rng = np.random.default_rng(4)
        a = rng.random((30, 40, 3)).astype(np.float32)
        b = (a * 0.9 + 0.05).astype(np.float32)
        metric.write_image(self.path("a.exr"), a)
        metric.write_image(self.path("b.exr"), b)
        out = metric.image_errors(self.path("a.exr"), self.path("b.exr"), encoding="linear",
                               filtered_output=self.path("fa.exr"))
        la, lb = metric.brightness(a, "linear"), metric.brightness(b, "linear")
        self.assertAlmostEqual(out["rms"], metric.rms_difference(la, lb), places=12)
        self.assertAlmostEqual(out["dog"], metric.rms_difference(metric.dog_filter(la), metric.dog_filter(lb)), places=12)
        self.assertEqual((out["width"], out["height"]), (40, 30))
        written = metric.read_image(self.path("fa.exr"))[:, :, 0]
        np.testing.assert_allclose(written, metric.dog_filter(la), atol=1e-6)
        same = metric.image_errors(self.path("a.exr"), self.path("a.exr"))
        self.assertEqual((same["dog"], same["rms"]), (0.0, 0.0))

    def test_missing_file_raises(self):
        metric.write_image(self.path("a.exr"), np.zeros((4, 4, 3), dtype=np.float32))
        with self.assertRaisesRegex(ValueError, "not found.*missing.exr"):
            metric.image_errors(self.path("a.exr"), self.path("missing.exr"))

    def test_size_mismatch_of_files_raises(self):
        metric.write_image(self.path("a.exr"), np.zeros((4, 6, 3), dtype=np.float32))
        metric.write_image(self.path("b.exr"), np.zeros((6, 4, 3), dtype=np.float32))
        with self.assertRaisesRegex(ValueError, "differ in size"):
            metric.image_errors(self.path("a.exr"), self.path("b.exr"))

    def test_png_output_is_clipped_8_bit(self):
        metric.write_image(self.path("g.png"), np.array([[-1.0, 0.5, 2.0]]))
        back = metric.read_image(self.path("g.png"))[0, :, 0]
        np.testing.assert_allclose(back, [0.0, 128 / 255, 1.0], atol=1 / 255)


if __name__ == "__main__":
    unittest.main()
