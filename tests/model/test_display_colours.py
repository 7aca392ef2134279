"""The game-ready colours' array math (addon/model/display_colours.py) in plain Python.

run_tests.py puts build/addon/radiosity on sys.path, where the build copies
model/display_colours.py; it imports only numpy (PyOpenColorIO when there is one).
"""

import unittest

import numpy as np

from model import display_colours as dc


class SrgbTest(unittest.TestCase):
    def test_known_values(self):
        # IEC 61966-2-1: 0 -> 0, 1 -> 1, 0.18 -> 0.4614, the linear toe below 0.0031308.
        np.testing.assert_allclose(dc.srgb_encode([0.0, 1.0, 0.18, 0.001]),
                                   [0.0, 1.0, 0.46135612, 0.01292], rtol=1e-6)
        np.testing.assert_allclose(dc.srgb_decode([0.0, 1.0, 0.5, 0.02]),
                                   [0.0, 1.0, 0.21404114, 0.02 / 12.92], rtol=1e-6)

    def test_round_trip_and_continuity(self):
        x = np.linspace(0.0, 1.0, 1001)
        np.testing.assert_allclose(dc.srgb_decode(dc.srgb_encode(x)), x, atol=1e-12)
        # The two pieces meet at the knee (no jump bigger than the slope allows).
        knee = dc.srgb_encode([0.0031308 - 1e-9, 0.0031308 + 1e-9])
        self.assertLess(abs(knee[1] - knee[0]), 1e-6)

    def test_out_of_range_is_clamped(self):
        np.testing.assert_allclose(dc.srgb_encode([-1.0, 30.0]), [0.0, 1.0], atol=1e-12)


class GameColoursTest(unittest.TestCase):
    radiance = np.array([[0.0, 0.5, 1.0], [30.0, 2.0, 0.25], [-0.1, np.nan, np.inf]])

    def test_standard_is_exposed_and_clamped_radiance(self):
        out = dc.game_colours(self.radiance, dc.DisplaySettings())
        self.assertEqual(out.dtype, np.float32)
        np.testing.assert_allclose(out, [[0.0, 0.5, 1.0], [1.0, 1.0, 0.25], [0.0, 0.0, 1.0]], atol=1e-6)
        display = dc.display_encoded(self.radiance, dc.DisplaySettings())
        np.testing.assert_allclose(display[0], [0.0, 0.73535698, 1.0], atol=1e-6)

    def test_exposure_in_stops(self):
        out = dc.game_colours([[0.1, 0.2, 0.4]], dc.DisplaySettings(exposure=1.0))
        np.testing.assert_allclose(out, [[0.2, 0.4, 0.8]], atol=1e-6)
        out = dc.game_colours([[0.1, 0.2, 0.4]], dc.DisplaySettings(exposure=-2.0))
        np.testing.assert_allclose(out, [[0.025, 0.05, 0.1]], atol=1e-6)

    def test_always_in_unit_range(self):
        rng = np.random.default_rng(1)
        values = rng.exponential(3.0, size=(1000, 3))
        for settings in (dc.DisplaySettings(exposure=3.0), dc.DisplaySettings(view="Raw"),
                         dc.DisplaySettings(gamma=2.0), dc.DisplaySettings(view="AgX")):
            out = dc.game_colours(values, settings)
            self.assertTrue(np.all((out >= 0.0) & (out <= 1.0)), settings.view)

    def test_gamma_applies_to_display_values(self):
        display = dc.display_encoded([[0.18, 0.18, 0.18]], dc.DisplaySettings(gamma=2.0))
        np.testing.assert_allclose(display, np.sqrt(dc.srgb_encode(0.18)) * np.ones((1, 3)), atol=1e-9)

    def test_other_views_use_their_transform_or_fall_back(self):
        missing = dc.DisplaySettings(view="Filmic")
        self.assertTrue(missing.fallback)
        np.testing.assert_allclose(dc.game_colours(self.radiance[:2], missing),
                                   dc.game_colours(self.radiance[:2], dc.DisplaySettings()), atol=1e-7)
        # A transform is applied after exposure, to the exposed linear values.
        seen = []

        def halve(rgb):
            seen.append(np.array(rgb))
            return np.asarray(rgb) * 0.5

        given = dc.DisplaySettings(exposure=1.0, view="Filmic", transform=halve)
        self.assertFalse(given.fallback)
        display = dc.display_encoded([[0.25, 0.5, 4.0]], given)
        np.testing.assert_allclose(seen[0], [[0.5, 1.0, 8.0]])
        np.testing.assert_allclose(display, [[0.25, 0.5, 1.0]])
        self.assertFalse(dc.DisplaySettings(view="Standard").fallback)
        self.assertFalse(dc.DisplaySettings(view="Raw").fallback)


class OcioTest(unittest.TestCase):
    def test_missing_config_gives_no_transform(self):
        self.assertIsNone(dc.ocio_display("/nonexistent/config.ocio", "sRGB", "Filmic"))
        self.assertIsNone(dc.ocio_display("", "sRGB", "Filmic"))


if __name__ == "__main__":
    unittest.main()
