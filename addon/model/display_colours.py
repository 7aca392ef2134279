"""Display-ready ("game-ready") colours from the solver's radiance: array math, no bpy.

The solver's radiance is scene-linear and unbounded (a light source is 30 times
brighter than a white wall). A game engine, or a glTF file (whose COLOR_0 must
lie in [0, 1]), needs the picture the user sees in Blender instead: radiance
times 2^exposure, through the scene's view transform, clamped to the display's
[0, 1].

`display_encoded` gives that picture as display values (what a monitor is sent:
sRGB-encoded for the Standard view). What the bake writes is `game_colours`: the
same picture decoded back to linear with the sRGB transfer function, because
every consumer of a colour attribute takes it as linear: glTF defines COLOR_0 as
linear (an engine multiplies it into its linear shading, then encodes the frame
to sRGB, so the screen shows `display_encoded`), Blender's FBX exporter encodes
the attribute to 8-bit sRGB itself, and Blender shows the attribute through the
Standard view as the same picture. With the Standard view, `game_colours` is
simply the exposed radiance clamped to [0, 1].

The Standard view is the sRGB transfer function, computed here. Other views
(Filmic, AgX, ...) are OpenColorIO transforms: `ocio_display` builds one from a
config file when PyOpenColorIO can be imported, and the caller falls back to
Standard otherwise (`DisplaySettings.fallback`).
"""

import os

import numpy as np

STANDARD = "Standard"
# Views whose display values are the scene-linear values themselves (clamped).
RAW_VIEWS = ("Raw",)


def srgb_encode(linear):
    """The sRGB transfer function (IEC 61966-2-1), linear -> display, of values in [0, 1]."""
    x = np.clip(np.asarray(linear, dtype=np.float64), 0.0, 1.0)
    return np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1.0 / 2.4) - 0.055)


def srgb_decode(encoded):
    """The inverse of srgb_encode: display -> linear, of values in [0, 1]."""
    v = np.clip(np.asarray(encoded, dtype=np.float64), 0.0, 1.0)
    return np.where(v <= 0.04045, v / 12.92, np.power((v + 0.055) / 1.055, 2.4))


class DisplaySettings:
    """How to turn radiance into display values: exposure in stops (the add-on's
    and the scene's added), the view transform's name, a gamma applied to the
    display values (Blender's view_settings.gamma: v ** (1 / gamma)), and for
    views other than Standard and Raw, `transform`: a function of (N, 3) linear
    values returning (N, 3) display values (ocio_display), or None, in which case
    Standard is used and `fallback` says so."""

    def __init__(self, exposure=0.0, view=STANDARD, gamma=1.0, transform=None):
        self.exposure = float(exposure)
        self.view = view
        self.gamma = float(gamma) if gamma else 1.0
        self.transform = transform

    @property
    def fallback(self):
        """True when the view needs a transform that is missing (Standard is used)."""
        return self.view not in (STANDARD,) + RAW_VIEWS and self.transform is None


def display_encoded(radiance, settings):
    """(N, 3) display values in [0, 1] of (N, 3) linear radiance under `settings`."""
    rgb = np.asarray(radiance, dtype=np.float64).reshape(-1, 3)
    exposed = np.nan_to_num(rgb, nan=0.0, posinf=np.finfo(np.float32).max) * 2.0 ** settings.exposure
    exposed = np.maximum(exposed, 0.0)
    if settings.view in RAW_VIEWS:
        shown = exposed
    elif settings.view == STANDARD or settings.transform is None:
        shown = srgb_encode(exposed)
    else:
        shown = np.asarray(settings.transform(exposed), dtype=np.float64).reshape(-1, 3)
    shown = np.clip(np.nan_to_num(shown, nan=0.0), 0.0, 1.0)
    if settings.gamma != 1.0:
        shown = np.power(shown, 1.0 / settings.gamma)
    return shown


def game_colours(radiance, settings):
    """(N, 3) float32 linear colours in [0, 1] that show as display_encoded(radiance)
    through the sRGB transfer function: what the game-ready bake writes."""
    return srgb_decode(display_encoded(radiance, settings)).astype(np.float32)


# --- OpenColorIO -------------------------------------------------------------------------

def ocio_available():
    """Whether PyOpenColorIO can be imported (bundled with official Blender 4.0+)."""
    try:
        import PyOpenColorIO  # noqa: F401
    except ImportError:
        return False
    return True


def ocio_display(config_path, display, view, look=None):
    """A function of (N, 3) scene-linear values returning their (N, 3) display values
    through OpenColorIO's display/view transform (`look` applied when given and not
    'None'), or None when PyOpenColorIO or the config is missing or the view or
    display is unknown to it."""
    try:
        import PyOpenColorIO as OCIO
    except ImportError:
        return None
    if not config_path or not os.path.isfile(config_path):
        return None
    try:
        config = OCIO.Config.CreateFromFile(config_path)
        if display not in config.getDisplays():
            display = config.getDefaultDisplay()
        if view not in config.getViews(display):
            return None
        pipeline = OCIO.LegacyViewingPipeline()
        pipeline.setDisplayViewTransform(OCIO.DisplayViewTransform(
            src=OCIO.ROLE_SCENE_LINEAR, display=display, view=view))
        if look and look != "None":
            pipeline.setLooksOverrideEnabled(True)
            pipeline.setLooksOverride(look)
        processor = pipeline.getProcessor(config).getDefaultCPUProcessor()
    except Exception:  # an OCIO error: an unknown look, a broken config
        return None

    def transform(linear):
        rgb = np.ascontiguousarray(np.asarray(linear, dtype=np.float32).reshape(-1, 3))
        processor.applyRGB(rgb)
        return rgb

    return transform
