"""Blender's point, spot and sun lights and a uniform world colour in the solver's units, free of `bpy`.

The solver's unit (DESIGN.md section 3) is the radiance a Cycles render shows with the
Standard view transform at exposure 0; a surface gathers H (= irradiance / pi in those
units) and shows L = L_e + rho H. The functions below turn a light's Blender settings
(plain values read from a `bpy.types.Light`; `version` is `bpy.app.version`, a tuple like
(3, 4, 1)) into the numbers the solver's direct light needs:

    point / spot, radius 0   H = I cos(theta) / d^2                        (intensity I, rgb)
    point / spot, radius r   H = I cos(theta) / (d^2 + r^2)   shape 'DISK'   (default)
                             H = I cos(theta) / d^2           shape 'SPHERE' (4.x, soft falloff off)
                             (while the light is wholly above the receiver's horizon;
                             point_light_h evaluates both)
    spot                     I times spot_attenuation(cos of the angle to the spot's axis)
    sun                      H = irradiance cos(theta)
    world (uniform)          H = world_radiance on a surface open to the whole sky

d is the distance to the light's centre, theta the angle of incidence at the receiver.
The radius is Blender's `shadow_soft_size`, in metres, in every version; the object's
(uniform) scale changes neither it nor the intensity (measured). A spot's non-uniform
scale, which Cycles 4.x uses to squash the cone, is not modelled. 'DISK' is a disk of
that radius that always faces the receiver and emits radiance L = I / r^2; 'SPHERE' a
sphere of that radius emitting L.

Measured in Cycles, not recalled (tests/blender/test_light_units.py, which runs in every
tested Blender and prints these numbers as `[measure]` lines): a white Diffuse BSDF plane,
direct light only (max_bounces 0), an orthographic camera looking down, 64 x 64 pixels,
a pixel filter of 0.01 px so every pixel samples its centre, the prediction evaluated
per pixel and the means over pixel sets compared.

    quantity (power P, strength S)      Blender 3.4.1           4.5.15 and 5.0.1
    point, r = 0: 4 pi^2 I / P          1.0000 (d = 1, 2; normal and 35-42 deg incidence)
    point, r > 0, measured / DISK       1.0000 (r 0.25 at d = 0.5, 0.75; r 0.1 at d = 0.2;
                                        r 0.25 at d = 0.5 and 35 deg incidence (/ SPHERE
                                        0.8555); r 0.25 with object scale 2: unchanged)
                  measured / SPHERE     0.8031 (d = 2r), 0.9018 (d = 3r): the disk
    point, soft falloff off             -                       / SPHERE 1.0000,
                                                                / DISK 1.2452 (2r), 1.1090 (3r),
                                                                1.1690 (2r, 35 deg incidence)
    spot, r 0.25 at d = 0.5 / its shape 1.0000 (DISK)           1.0000 (DISK; SPHERE w/o soft falloff)
    spot attenuation                    cos x smoothstep        smoothstep (no cosine)
      60 deg blend 0.3 at 10-18 deg     0.9679 (= mean cos)     1.0000
      in the band, 25.5-26.5 deg        0.8061                  0.8970 (5.0.1: 0.8971)
      27-28.5 deg                       0.4006                  0.4523
      29-29.8 deg                       0.0471                  0.0540 (5.0.1: 0.0542)
      outside (31-40 deg)               0                       0
      90 deg blend 1 at 30-32 deg       0.4478                  0.5219
      60 deg blend 0 at 27-29.7 deg     0.8801 (cos)            1.0000 (a step)
    sun: pi H / (S cos theta)           2c / (1 + c),           1.0000 (angles 0, 10, 90 deg;
                                        c = cos(angle / 2):     tilts 0, 30, 60 deg)
                                        0.9981 at 10 deg, 0.96891 at 40 deg,
                                        0.8284 at 90 deg (tilt 30), 0.2959 at 160 deg
    world: H / (colour x strength)      1.0000                  1.0000
    exposure e                          (none)                  x 2^e (point 1.5, sun -1)
    normalize off                       (none)                  r = 0: I = P / pi^2 (x 4);
                                                                r > 0: I = P r^2 / pi (L = P / pi);
                                                                sun: H = S sin^2(angle / 2)
    temperature (use_temperature)       (none)                  colour x temperature_color

(every "measured / predicted" of the test is 1.0000 but for the noisy lights with a
radius, 0.9998 to 1.0002, and the 5.0.1 spot's last 0.2 deg before the cone's edge, 1.0045.)

So I = P / (4 pi^2) for a point or spot light (on the spot's axis) in all three, with or
without a radius: the power is divided by nothing that depends on the radius (the radiance
of a light with radius is L = P / (4 pi^2 r^2)), and the radius only changes the shape's
near field. Source read (the measurements decide): Cycles' intern/cycles/scene/light.cpp
of a 4.x with `normalize` (eval_fac = 1 / (pi A), A = 4 pi r^2 or 4 when r = 0;
the sun's 1 / (pi sin^2(angle / 2)); spot_smooth = 1 / ((1 - c0) blend)),
kernel/light/point.h and spot.h of blender/blender main (a sphere where the kernel's
`is_sphere` is set, else a disk facing the receiver; spot attenuation smoothstepf((cos -
c0) spot_smooth), no cosine), and a 3.x kernel/light/common.h `spot_light_attenuation`
(attenuation = cos, times smoothstepf(t / spot_smooth) in the band); none pinned to the
exact 3.4 / 4.5 / 5.0 commits. That `is_sphere` is "soft falloff off" is measured.
"""

import math

import numpy as np

# I / P of a point light and of a spot light on its axis (all versions, normalized).
POINT_INTENSITY_FACTOR = 1.0 / (4.0 * math.pi ** 2)
# pi H / S of a sun facing the receiver (4.x; 3.x also has the angle term of sun_light).
SUN_FACTOR = 1.0 / math.pi


def _version(version):
    parts = tuple(int(v) for v in tuple(version)[:3])
    return parts + (0,) * (3 - len(parts))


def _cycles_4(version):
    """Cycles 4.0 changed the spot attenuation, the sun's and added exposure, normalize and
    soft falloff; 4.0 to 4.4 are not measured here, 4.5 and 5.0 are."""
    return _version(version) >= (4, 0, 0)


def _colour(colour):
    return np.asarray(colour, dtype=float).reshape(3)


def _point_factor(version, radius, exposure, normalize):
    """I / P of a point or spot light."""
    factor = POINT_INTENSITY_FACTOR
    if _cycles_4(version):
        factor *= 2.0 ** exposure
        if not normalize:
            # Cycles' 1 / A left out: A = 4 pi r^2, or 4 when r = 0.
            factor *= 4.0 if radius <= 0.0 else 4.0 * math.pi * radius * radius
    return factor


def point_light_shape(version, soft_falloff=True):
    """What a point or spot light with a radius is in Cycles: 'DISK' (a disk of the radius
    facing the receiver; Blender 3.x, and 4.x with `use_soft_falloff` on, its default) or
    'SPHERE' (4.x with `use_soft_falloff` off). Measured on the axis at d = 2r and 3r:
    3.4.1, 4.5.15, 5.0.1 (soft falloff) measured / disk 1.0000, / sphere 0.8031 and 0.9017;
    4.5.15, 5.0.1 without soft falloff / sphere 1.0000, / disk 1.2452 and 1.1090."""
    if not _cycles_4(version):
        return 'DISK'
    return 'DISK' if soft_falloff else 'SPHERE'


def point_light(version, power, colour, radius, exposure=0.0, normalize=True, soft_falloff=True):
    """A Blender point light (`energy` = power in W, `color`, `shadow_soft_size` = radius,
    and in 4.x `exposure`, `normalize`, `use_soft_falloff`) in the solver's units.

    Returns a dict:
      intensity  rgb I: a receiver at distance d from a radius-0 light, at incidence theta,
                 gathers H = I cos(theta) / d^2. I = P colour / (4 pi^2) (measured
                 4 pi^2 I / P = 1.0000 in 3.4.1, 4.5.15, 5.0.1), times 2^exposure (4.x),
                 times 4 (r = 0) or 4 pi r^2 (r > 0) with `normalize` off (4.x).
      radius     metres (shadow_soft_size as given; the same in every version).
      shape      point_light_shape(version, soft_falloff): with a radius the light is a disk
                 facing the receiver (H = I cos / (d^2 + r^2)) or a sphere (H = I cos / d^2),
                 both of radiance L = I / r^2; point_light_h evaluates it.
    `colour` is the light's linear colour, with the temperature colour applied where the
    light uses one (compat.light_colour)."""
    return {
        "intensity": _point_factor(version, radius, exposure, normalize) * power * _colour(colour),
        "radius": float(radius),
        "shape": point_light_shape(version, soft_falloff),
    }


def point_light_h(intensity, radius, shape, distance, cos_incidence):
    """H gathered from a point (or spot, on its axis) light of intensity I (rgb), `radius`
    and `shape` by a receiver at `distance` from the light's centre whose normal makes
    acos(cos_incidence) with the direction to the centre, while the light is wholly above
    the receiver's horizon: I cos / d^2 for r = 0 or a 'SPHERE', I cos / (d^2 + r^2) for a
    'DISK' (the disk subtends a cone of sin^2 = r^2 / (d^2 + r^2)). `distance` and
    `cos_incidence` may be arrays; the result then has a last axis of 3."""
    intensity = np.asarray(intensity, dtype=float)
    d2 = np.asarray(distance, dtype=float) ** 2
    if shape == 'DISK':
        d2 = d2 + radius * radius
    ratio = np.maximum(np.asarray(cos_incidence, dtype=float), 0.0) / d2
    return np.multiply.outer(ratio, intensity) if intensity.ndim else ratio * intensity


def smoothstep(x):
    """3 x^2 - 2 x^3 of x clamped to [0, 1] (Cycles' smoothstepf)."""
    x = np.clip(x, 0.0, 1.0)
    return x * x * (3.0 - 2.0 * x)


def spot_attenuation(version, cos_angle, spot_size, spot_blend):
    """The factor that multiplies a spot light's intensity in a direction at angle
    acos(cos_angle) from its axis (numpy; `cos_angle` may be an array).

    With c0 = cos(spot_size / 2) and the band width w = (1 - c0) spot_blend (in cos):
        Cycles 4.x (4.5.15, 5.0.1):  smoothstep((cos - c0) / w)
        Cycles 3.x (3.4.1):          cos x smoothstep((cos - c0) / w)
    0 outside the cone (cos <= c0); a step where w = 0. Measured at 0-2, 10-18, in the
    band (25.5-26.5, 27-28.5, 29-29.8 deg) and outside (31-40 deg) of a 60 deg spot of
    blend 0.3, and across a 90 deg spot of blend 1: within 0.03 % of the formula of the
    version (5.0.1 within 0.5 % at the cone's very edge, where H is 3.5 % of the axis'),
    while the other version's formula is off by up to 12 % (tests/blender/test_light_units.py).
    With a radius Cycles takes the angle of each emitted direction (from the point of the
    disk or sphere to the receiver); taking the centre's is exact for r = 0."""
    cos_angle = np.asarray(cos_angle, dtype=float)
    cos_half = math.cos(spot_size / 2.0)
    width = (1.0 - cos_half) * spot_blend
    t = cos_angle - cos_half
    if width > 0.0:
        attenuation = smoothstep(t / width)
    else:
        attenuation = np.ones_like(t)
    attenuation = np.where(t > 0.0, attenuation, 0.0)
    if not _cycles_4(version):
        attenuation = attenuation * cos_angle
    return attenuation


def spot_light(version, power, colour, radius, spot_size, spot_blend, exposure=0.0, normalize=True,
               soft_falloff=True):
    """A Blender spot light in the solver's units: point_light's dict (`intensity` on the
    axis: P colour / (4 pi^2), the same as a point light's; the cone does not concentrate
    the power), plus
      cos_half_angle   cos(spot_size / 2): no light where the cos to the axis is below it
      blend            spot_blend as given
      cos_blend_width  (1 - cos_half_angle) spot_blend: the band of cos over which the
                       attenuation rises from 0 to 1 (a smoothstep)
      cos_factor       True where the attenuation also has the cosine to the axis (3.x)
    The attenuation itself is spot_attenuation(version, cos, spot_size, spot_blend)."""
    result = point_light(version, power, colour, radius, exposure, normalize, soft_falloff)
    cos_half = math.cos(spot_size / 2.0)
    result.update({
        "cos_half_angle": cos_half,
        "blend": float(spot_blend),
        "cos_blend_width": (1.0 - cos_half) * spot_blend,
        "cos_factor": not _cycles_4(version),
    })
    return result


def sun_light(version, strength, colour, angle, exposure=0.0, normalize=True):
    """A Blender sun light (`energy` = strength, `color`, `angle`, and in 4.x `exposure`,
    `normalize`) in the solver's units. Returns a dict:
      irradiance  rgb: a receiver at incidence theta to the sun's direction gathers
                  H = irradiance cos(theta) (while the sun's disk is above its horizon).
                  4.x: S colour / pi (measured pi H / (S cos) = 1.0000 at angles 0, 10 and
                  90 deg, tilts 0, 30, 60 deg in 4.5.15 and 5.0.1), times 2^exposure, and
                  with `normalize` off times pi sin^2(angle / 2). 3.x: S colour / pi times
                  2 c / (1 + c), c = cos(angle / 2) (measured 0.9981 at 10 deg, 0.96891 at
                  40, 0.82843 at 90, 0.2959 at 160; 1 for a sun of angle 0).
      angle       the sun disk's angular diameter in radians (Blender's `angle`)."""
    scale = SUN_FACTOR * strength
    if not _cycles_4(version):
        cos_half = math.cos(angle / 2.0)
        scale *= 2.0 * cos_half / (1.0 + cos_half)
    else:
        scale *= 2.0 ** exposure
        if not normalize and angle > 0.0:
            scale *= math.pi * math.sin(angle / 2.0) ** 2
    return {"irradiance": scale * _colour(colour), "angle": float(angle)}


def world_radiance(colour, strength):
    """Radiance (rgb) of a uniform world: the Background shader's colour times its strength.
    A surface open to the whole sky gathers H = this (measured H / (colour strength) =
    1.0000 in 3.4.1, 4.5.15 and 5.0.1), so it shows rho times it."""
    return float(strength) * _colour(colour)
