"""What the Quality slider means for each oracle, in words: the lines the panel
shows under it.

Quality sets the threshold an oracle's criterion is compared with, log-spaced
between the oracle's coarse and fine ends (the native quality_threshold, the
one place they are defined). Each text states that threshold as what it allows
the eye to see: a brightness difference in per cent of the brightness the eye
adapts to (the solver's adaptation radiance), or in just noticeable
differences. Standard and Gradient weigh a link's criterion by its receiver's
share of the scene's area (A_p / A; for Gradient A_p / sqrt(A)), so their
allowance depends on the patch's size: the text states it for a patch of
PATCH_SHARE of the area. A headline fits the panel's value column at the
default width, the detail under it is wrapped (tests/blender/test_addon.py).
"""

import math

from . import oracles

# The patch size the area-weighted oracles' texts speak of: a share of the scene's area.
PATCH_SHARE = 0.01
PATCH_WORDS = "1 % of the area"
# Weber's law: one just noticeable difference is about this fraction of the
# brightness around (native/core/solve/oracle.h, kWeberFraction).
WEBER_PERCENT = 2


def _number(value):
    """Two significant digits and no exponent (thresholds of quality > 0 stay above 1e-5)."""
    value = float("%.2g" % value)  # 9.99998 is 10, not 10.0
    if value >= 10.0:
        return "%.0f" % value
    if value >= 1.0:
        return "%.1f" % value
    return "%.2g" % value


def quality_meaning(oracle, threshold):
    """The panel's (headline, detail) for `oracle` (the add-on's enum identifier) at
    `threshold`; the detail says what the headline's number is, or is empty."""
    if not math.isfinite(threshold):
        return "No refinement: the coarsest lighting", ""
    name = oracles.name_of(oracle)
    if name == oracles.NOTICEABLE:
        # The mesh's reconstruction error in just noticeable differences at the receiver.
        return ("Differences below %s JND" % _number(threshold),
                "about %s %% of the brightness around (1 JND, the least step seen: %d %%)"
                % (_number(WEBER_PERCENT * threshold), WEBER_PERCENT))
    if name == oracles.PERCEPTUAL:
        # Tangent misses (eq. 28) over the adaptation radiance.
        return ("Shading errors below %s %%" % _number(100.0 * threshold),
                "of the brightness, where the mesh's straight shading misses the light")
    if name == oracles.STANDARD:
        # (L_max - L_min) A_p / (L_ref A): on a patch of share a the brightness a link
        # brings may differ by threshold / a of L_ref from one end to the other.
        return ("Light uneven below %s %%" % _number(100.0 * threshold / PATCH_SHARE),
                "of the brightness, for one link's light across a patch of %s" % PATCH_WORDS)
    if name == oracles.GRADIENT:
        # |change of slope| A_p / (L_ref sqrt(A)) = (change of slope x side) sqrt(a) / L_ref:
        # the crease a link's light makes across a patch of share a is threshold / sqrt(a).
        return ("Light creases below %s %%" % _number(100.0 * threshold / math.sqrt(PATCH_SHARE)),
                "of the brightness: one link's light bending (its slope changing) over %s"
                % PATCH_WORDS)
    return "", ""


def quality_text(settings, native_module):
    """The (headline, detail) for the scene's settings; empty when the solver cannot
    load (the panel says why elsewhere)."""
    if native_module is None:
        return "", ""
    threshold = native_module.quality_threshold(oracles.name_of(settings.oracle), settings.quality)
    return quality_meaning(settings.oracle, threshold)
