"""Energy at the default settings: the furnace and a lit closed room, for every
oracle at qualities 0.3, 0.5 and 0.8 and reflectances up to 0.99.

In a closed room every bit of light is absorbed somewhere: the power the
surfaces absorb must equal what the light emits. White rooms amplify any loss
per bounce by 1 / (1 - rho), so a 0.3 % loss per bounce (what the solver lost
before its transport was balanced, native/README.md) becomes 0.6 % at
rho = 0.5 and 5 % at 0.99, and the furnace (every face emitting and
reflecting alike) was 1.4 % off at 0.9.
"""

import math
import pathlib
import sys
import unittest

import numpy as np

sys.path.insert(0, str(pathlib.Path(__file__).resolve().parent))

import _radiosity as rad  # noqa: E402
from synthetic_scenes import SceneBuilder, add_box  # noqa: E402
from test_solver import ORACLES, absorbed_power, closed_box  # noqa: E402

QUALITIES = (0.3, 0.5, 0.8)
LAMP_RADIANCE = 5.0


def tolerance(rho):
    return 1e-2 if rho > 0.95 else 1e-3


def lit_room(rho):
    """A closed 4 x 4 x 3 m room, reflectance rho everywhere, lit by a 0.6 m
    square one-sided lamp filling a hole in the ceiling (so nothing hides
    behind it)."""
    b = SceneBuilder()
    add_box(b, (0, 0, 0), (4, 4, 3), reflectance=rho, inward=True, omit=("top",))
    for x0, x1, y0, y1 in ((0, 4, 0, 1.7), (0, 4, 2.3, 4), (0, 1.7, 1.7, 2.3), (2.3, 4, 1.7, 2.3)):
        b.polygon([(x0, y1, 3), (x1, y1, 3), (x1, y0, 3), (x0, y0, 3)], reflectance=rho)  # facing down
    b.polygon([(1.7, 2.3, 3), (2.3, 2.3, 3), (2.3, 1.7, 3), (1.7, 1.7, 3)], reflectance=rho, emission=LAMP_RADIANCE,
              two_sided=False)
    return b


class FurnaceAtDefaults(unittest.TestCase):
    def test_uniform_radiance_everywhere(self):
        for rho in (0.5, 0.9, 0.99):
            for oracle in ORACLES:
                for quality in QUALITIES:
                    with self.subTest(rho=rho, oracle=oracle, quality=quality):
                        result = rad.solve(closed_box(rho, 0.7).scene(rad), oracle=oracle, quality=quality)
                        error = np.abs(result.radiance / (0.7 / (1 - rho)) - 1).max()
                        print("[furnace] rho %.2f %-10s q %.1f: worst %.1e, %d elements"
                              % (rho, oracle, quality, error, result.stats["elements"]), flush=True)
                        self.assertLess(error, tolerance(rho))


class LitRoomBalance(unittest.TestCase):
    def test_absorbed_equals_emitted(self):
        emitted = math.pi * LAMP_RADIANCE * 0.36
        for rho in (0.5, 0.9, 0.99):
            for oracle in ORACLES:
                for quality in QUALITIES:
                    with self.subTest(rho=rho, oracle=oracle, quality=quality):
                        b = lit_room(rho)
                        result = rad.solve(b.scene(rad), oracle=oracle, quality=quality)
                        ratio = absorbed_power(b, result) / emitted
                        print("[balance] rho %.2f %-10s q %.1f: absorbed / emitted %.5f, %d elements, %d iterations"
                              % (rho, oracle, quality, ratio[0], result.stats["elements"],
                                 result.stats["iterations"]), flush=True)
                        np.testing.assert_allclose(ratio, 1.0, rtol=tolerance(rho))
                        self.assertGreater(result.stats["elements"], 30)  # refined: the balance is tested with refinement

    def test_white_room_converges_in_a_few_dozen_iterations(self):
        # Jacobi alone gains a factor rho per iteration: about 900 iterations
        # at rho = 0.99 (tolerance 1e-6). The tail extrapolation (convergence.h)
        # takes the remaining geometric series at once.
        result = rad.solve(lit_room(0.99).scene(rad), oracle="perceptual", quality=0.3)
        self.assertLess(result.stats["iterations"], 200)
        self.assertLess(result.stats["residual"], 1e-6)


if __name__ == "__main__":
    unittest.main()
