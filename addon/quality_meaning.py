"""What the Quality slider means for each oracle, in words: the line the panel
shows under it.

Quality sets the threshold an oracle's criterion is compared with, log-spaced
between the oracle's coarse and fine ends (the native quality_threshold, the
one place they are defined). Each text states that threshold in the oracle's
own terms, relative as the solver measures it: to the brightness the eye adapts
to (the mean radiance of the lit surfaces) and, for the area-weighted oracles
(Standard, Gradient), to the scene's area. The texts fit the panel's value
column at the default width (tests/blender/test_addon.py).
"""

import math


def _number(value):
    """Two significant digits, without an exponent where a reader needs none."""
    if value >= 0.1:
        return "%.2g" % value
    return "%.1e" % value


def quality_meaning(oracle, threshold):
    """The panel's text for `oracle` (the add-on's enum identifier) at `threshold`."""
    if not math.isfinite(threshold):
        return "No refinement: the coarsest lighting"
    if oracle == 'NOTICEABLE':
        # Just noticeable differences of the mesh's shading from the true lighting.
        return "Differences below %s JND" % _number(threshold)
    if oracle == 'PERCEPTUAL':
        # Tangent misses (eq. 28) over the adaptation radiance.
        return "Shading errors below %s %%" % _number(100.0 * threshold)
    if oracle == 'STANDARD':
        # Spread of a link's light times its receiver's share of the scene's area.
        return "Light spread below %s" % _number(threshold)
    if oracle == 'GRADIENT':
        # Change of slope times area over the scene's size.
        return "Slope change below %s" % _number(threshold)
    return ""


def quality_text(settings, native_module):
    """The text for the scene's settings; empty when the solver cannot load
    (the panel says why elsewhere)."""
    if native_module is None:
        return ""
    threshold = native_module.quality_threshold(settings.oracle.lower(), settings.quality)
    return quality_meaning(settings.oracle, threshold)
