"""Blender's point, spot and sun lights and a uniform world colour, measured in Cycles and
checked against the add-on's conversion (addon/model/light_units.py, whose docstring has the
table of what was measured in 3.4.1, 4.5.15 and 5.0.1).

A white Diffuse BSDF plane (40 m square at z = 0), direct light only (max_bounces 0),
an orthographic camera 1 cm above it looking down, 64 x 64 pixels, the Standard view
transform, a pixel filter of 0.01 px so each pixel samples its centre, no light
threshold. The conversion predicts H at each pixel's centre; the means over a set of
pixels (the centre, an oblique ring, an angle band of a spot) are compared, within 1 %
for lights of radius 0, the sun and the world (deterministic: a few samples), within
2 % for lights with a radius (128 samples, noise about 0.1 %). Cases:

    point, r = 0, d = 1 and 2: normal incidence and 35-42 deg (inverse square, cosine)
    point, r 0.25 at d = 0.5 (2r) and 0.75 (3r), r 0.1 at d = 0.2: 'DISK' vs 'SPHERE';
    r 0.25 at d = 0.5 at 35 deg incidence, and with object scale 2
    point with use_soft_falloff off (4.x), at 2r, 3r and 2r at 35 deg incidence
    spot 60 deg blend 0.3 and 90 deg blend 1 at the axis, inside, across the blend band,
    outside; a spot of radius 0.25 at d = 0.5 (both falloffs), predicted by integrating the
    attenuation over the directions the light's disk or sphere covers (cone_h)
    sun: strength 3 coloured, 1.5 with angle 10 deg facing and tilted 60 deg, 2 with
    angle 90 deg tilted 30 deg
    world (0.8, 0.4, 0.2) x 1.5 on the open plane
    4.x: exposure (point 1.5, sun -1), 3000 K temperature, normalize off (point r = 0 and
    0.1, sun of 10 deg); skipped where the light has no such setting (3.4)

`[measure]` lines (run_tests -v) print measured / predicted, the measured factor
4 pi^2 I / P, the ratios to both point-light shapes, and per spot angle band the measured
attenuation beside the 3.x and 4.x formulas.
"""

import math
import os
import tempfile
import unittest

import bpy
import numpy as np

from radiosity import compat
from radiosity.model import light_units
from test_light_conversion import add_mesh, diffuse

RESOLUTION = 64
TOLERANCE = 0.01
NOISY_TOLERANCE = 0.02
VERSION = tuple(bpy.app.version)


def has(kind, name):
    """Whether Blender's lights of `kind` ('POINT', 'SUN', ...) have setting `name`."""
    cls = {'POINT': bpy.types.PointLight, 'SPOT': bpy.types.SpotLight, 'SUN': bpy.types.SunLight}[kind]
    return name in cls.bl_rna.properties


def remove(name):
    """Remove the light `name` and its objects, if still there."""
    light = bpy.data.lights.get(name)
    if light is not None:
        for obj in [o for o in bpy.data.objects if o.data == light]:
            bpy.data.objects.remove(obj)
        bpy.data.lights.remove(light)


def set_radius(light, radius):
    light.shadow_soft_size = radius


def cone_h(version, conv, shape, receiver, centre, light, steps=24):
    """H at a receiver facing +z from a spot light with a radius: (L / pi) times the integral,
    over the cone of directions in which the receiver sees the light's disk or sphere, of the
    spot attenuation of each direction times its cosine to the normal (L = I / r^2, the
    light's radiance). Midpoint rule in (cos, azimuth)."""
    receiver, centre = np.asarray(receiver, float), np.asarray(centre, float)
    r = conv["radius"]
    axis = centre - receiver
    dist = np.linalg.norm(axis)
    axis /= dist
    sin_a = r / dist if shape == 'SPHERE' else r / math.hypot(dist, r)
    cos_a = math.sqrt(1.0 - sin_a * sin_a)
    u = np.cross(axis, (1.0, 0.0, 0.0) if abs(axis[0]) < 0.9 else (0.0, 1.0, 0.0))
    u /= np.linalg.norm(u)
    v = np.cross(axis, u)
    c = cos_a + (1.0 - cos_a) * (np.arange(steps) + 0.5) / steps
    phi = 2.0 * math.pi * (np.arange(2 * steps) + 0.5) / (2 * steps)
    c, phi = np.meshgrid(c, phi)
    s = np.sqrt(1.0 - c * c)
    w = (c[..., None] * axis + (s * np.cos(phi))[..., None] * u + (s * np.sin(phi))[..., None] * v)
    # Light leaves the light along -w; the spot points along -z.
    cos_axis = w[..., 2]
    att = light_units.spot_attenuation(version, cos_axis, light.spot_size, light.spot_blend)
    cos_n = np.maximum(w[..., 2], 0.0)
    d_omega = (1.0 - cos_a) * 2.0 * math.pi / c.size
    radiance = conv["intensity"][0] / (r * r)
    return radiance / math.pi * float(np.sum(att * cos_n)) * d_omega


class LightUnitsTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = cls.scene = bpy.context.scene
        scene.render.engine = 'CYCLES'
        scene.cycles.device = 'CPU'
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.max_bounces = 0   # direct light only
        scene.cycles.light_sampling_threshold = 0.0   # no probabilistic termination (noise)
        scene.cycles.filter_width = 0.01   # each pixel samples its centre: predictable per pixel
        scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
        scene.render.resolution_percentage = 100
        scene.view_settings.view_transform = 'Standard'
        scene.view_settings.look = 'None'
        scene.view_settings.exposure = 0.0
        scene.view_settings.gamma = 1.0
        world = cls.world = bpy.data.worlds.new("Black")
        world.use_nodes = True
        cls.background = world.node_tree.nodes["Background"]
        cls.background.inputs[0].default_value = (0, 0, 0, 1)
        cls.background.inputs[1].default_value = 1.0
        scene.world = world
        add_mesh(scene, "Plane", [(-20, -20, 0), (20, -20, 0), (20, 20, 0), (-20, 20, 0)],
                 diffuse("White", 1.0))
        camera = cls.camera = bpy.data.cameras.new("Camera")
        camera.type = 'ORTHO'
        camera.clip_start, camera.clip_end = 0.001, 1.0
        cam = cls.cam = bpy.data.objects.new("Camera", camera)
        scene.collection.objects.link(cam)
        scene.camera = cam
        cls.tmp = tempfile.TemporaryDirectory(prefix="radiosity-light-units-")

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    # --- scene helpers -------------------------------------------------------------

    def view(self, cx, cy, size):
        """The camera looks straight down at the plane, centred on (cx, cy), `size` m wide.
        Returns the world x, y of the pixel centres (arrays of RESOLUTION x RESOLUTION)."""
        self.cam.location = (cx, cy, 0.01)
        self.camera.ortho_scale = size
        u = ((np.arange(RESOLUTION) + 0.5) / RESOLUTION - 0.5) * size
        x, y = np.meshgrid(cx + u, cy + u)   # image rows go up in y (bpy pixels start at the bottom)
        return x, y

    def render(self, samples):
        """Linear RGB of every pixel, RESOLUTION x RESOLUTION x 3 (row 0 at the bottom)."""
        scene = self.scene
        scene.cycles.samples = samples
        path = os.path.join(self.tmp.name, "measure.exr")
        scene.render.image_settings.file_format = 'OPEN_EXR'
        scene.render.image_settings.color_depth = '32'
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(path)
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        return pixels.reshape(RESOLUTION, RESOLUTION, 4)[:, :, :3].astype(float)

    def light(self, kind, location=(0, 0, 1), rotation=(0, 0, 0), **settings):
        light = bpy.data.lights.new(kind, kind)
        for key, value in settings.items():
            if key == "radius":
                set_radius(light, value)
            else:
                setattr(light, key, value)
        obj = bpy.data.objects.new(kind, light)
        obj.location, obj.rotation_euler = location, rotation
        self.scene.collection.objects.link(obj)
        self.addCleanup(remove, light.name)
        bpy.context.view_layer.update()
        return light

    def require(self, kind, *names):
        missing = [n for n in names if not has(kind, n)]
        if missing:
            self.skipTest("Blender %s lights have no %s" % (bpy.app.version_string, ", ".join(missing)))

    def compare(self, label, pixels, predicted, mask, tolerance=TOLERANCE, scale=None):
        """Mean measured vs mean predicted rgb over the pixels of `mask`; `scale` (if given)
        makes it an absolute comparison (|measured - predicted| <= tolerance * scale)."""
        measured = pixels[mask].mean(axis=0)
        expected = predicted[mask].mean(axis=0)
        if scale is None:
            ratio = measured / expected
            print("[measure] Blender %s, %s: measured / predicted = %s"
                  % (bpy.app.version_string, label, np.round(ratio, 4)), flush=True)
            np.testing.assert_allclose(measured, expected, rtol=tolerance, err_msg=label)
        else:
            print("[measure] Blender %s, %s: measured %s, predicted %s (scale %.4g)"
                  % (bpy.app.version_string, label, np.round(measured, 5), np.round(expected, 5), scale),
                  flush=True)
            np.testing.assert_allclose(measured, expected, atol=tolerance * scale, rtol=0, err_msg=label)
        return measured, expected

    # --- point lights ---------------------------------------------------------------

    def point_geometry(self, x, y, height):
        d = np.sqrt(x * x + y * y + height * height)
        return d, height / d

    def test_point_inverse_square_and_cosine(self):
        power, colour = 100.0, (1.0, 0.5, 0.25)
        for height in (1.0, 2.0):
            light = self.light('POINT', (0, 0, height), energy=power, color=colour, radius=0.0)
            x, y = self.view(0.0, 0.0, 2.0 * height)
            pixels = self.render(4)
            conv = light_units.point_light(VERSION, power, colour, 0.0)
            d, cos = self.point_geometry(x, y, height)
            predicted = light_units.point_light_h(conv["intensity"], 0.0, conv["shape"], d, cos)
            r = np.hypot(x, y) / height
            centre = r < 0.1
            oblique = (r > 0.7) & (r < 0.9)   # 35 to 42 degrees
            measured, _ = self.compare("point r=0 d=%g normal" % height, pixels, predicted, centre)
            self.compare("point r=0 d=%g oblique 35-42 deg" % height, pixels, predicted, oblique)
            d0, cos0 = d[centre], cos[centre]
            factor = (pixels[centre] * (d0 * d0 / cos0)[:, None]).mean(axis=0) / (power * np.array(colour))
            print("[measure] Blender %s, point r=0 d=%g: I / (P colour) = %s (4 pi^2 I / P = %s)"
                  % (bpy.app.version_string, height, np.round(factor, 6),
                     np.round(factor * 4 * math.pi ** 2, 4)), flush=True)
            remove(light.name)

    def near_point(self, kind, radius, distance, samples=128, label=None, scale=1.0, offset=0.0,
                   **settings):
        """A point (or downward spot) light of `radius` at `distance` above the plane, its
        object scaled by `scale`; compares the pixels around (offset, 0) with the version's
        shape (of the unscaled radius) and prints both shapes' ratios."""
        power = 100.0
        light = self.light(kind, (0, 0, distance), energy=power, radius=radius, **settings)
        if scale != 1.0:
            bpy.data.objects[light.name].scale = (scale,) * 3
            bpy.context.view_layer.update()
        x, y = self.view(offset, 0.0, 0.5 * distance)
        pixels = self.render(samples)
        soft = getattr(light, "use_soft_falloff", True)
        if kind == 'SPOT':
            conv = light_units.spot_light(VERSION, power, (1, 1, 1), radius, light.spot_size,
                                          light.spot_blend, soft_falloff=soft)
        else:
            conv = light_units.point_light(VERSION, power, (1, 1, 1), radius, soft_falloff=soft)
        mask = np.hypot(x - offset, y) < 0.2 * distance
        mask[1::2, :] = mask[:, 1::2] = False   # every other pixel: cone_h is slow
        d, cos = self.point_geometry(x[mask], y[mask], distance)
        measured = pixels[mask].mean()
        ratios = {}
        for shape in ('SPHERE', 'DISK'):
            if kind == 'SPOT':
                h = [cone_h(VERSION, conv, shape, (px, py, 0.0), (0, 0, distance), light)
                     for px, py in zip(x[mask], y[mask])]
            else:
                h = light_units.point_light_h(conv["intensity"][0], radius, shape, d, cos)
            ratios[shape] = measured / np.mean(h)
        label = label or "%s r=%g d=%g soft_falloff=%s%s" % (
            kind.lower(), radius, distance, soft, " object scale %g" % scale if scale != 1.0 else "")
        if offset:
            label += " at %.0f deg incidence" % math.degrees(math.atan2(offset, distance))
        print("[measure] Blender %s, %s: measured / sphere model = %.4f, / disk model = %.4f (%s)"
              % (bpy.app.version_string, label, ratios['SPHERE'], ratios['DISK'], conv["shape"]),
              flush=True)
        remove(light.name)
        self.assertAlmostEqual(ratios[conv["shape"]], 1.0, delta=NOISY_TOLERANCE, msg=label)

    def test_point_radius(self):
        self.near_point('POINT', 0.25, 0.5)
        self.near_point('POINT', 0.25, 0.75)
        self.near_point('POINT', 0.1, 0.2)
        # The object's scale changes neither the radius nor the intensity.
        self.near_point('POINT', 0.25, 0.5, scale=2.0)
        self.near_point('POINT', 0.25, 0.5, offset=0.35)

    def test_point_radius_hard_falloff(self):
        self.require('POINT', "use_soft_falloff")
        self.near_point('POINT', 0.25, 0.5, use_soft_falloff=False)
        self.near_point('POINT', 0.1, 0.3, use_soft_falloff=False)
        self.near_point('POINT', 0.25, 0.5, offset=0.35, use_soft_falloff=False)

    # --- spot lights ----------------------------------------------------------------

    def spot(self, spot_size, spot_blend, view, bins):
        power, height = 100.0, 1.0
        light = self.light('SPOT', (0, 0, height), energy=power, radius=0.0,
                           spot_size=spot_size, spot_blend=spot_blend)
        x, y = self.view(0.0, 0.0, view)
        pixels = self.render(4)
        conv = light_units.spot_light(VERSION, power, (1, 1, 1), 0.0, spot_size, spot_blend)
        d, cos = self.point_geometry(x, y, height)
        angle = np.degrees(np.arccos(cos))
        base = light_units.point_light_h(conv["intensity"], 0.0, conv["shape"], d, cos)
        predicted = base * light_units.spot_attenuation(VERSION, cos, spot_size, spot_blend)[..., None]
        axis_value = base[angle < 2].mean()
        for lo, hi in bins:
            mask = (angle >= lo) & (angle < hi)
            measured = pixels[mask].mean()
            both = {}
            for name, ver in (("3.x", (3, 4, 0)), ("4.x", (4, 0, 0))):
                att = light_units.spot_attenuation(ver, cos, spot_size, spot_blend)
                both[name] = (base[..., 0] * att)[mask].mean()
            print("[measure] Blender %s, spot size %.0f blend %.2f, %g-%g deg: measured attenuation %.4f, "
                  "3.x formula %.4f, 4.x formula %.4f"
                  % (bpy.app.version_string, math.degrees(spot_size), spot_blend, lo, hi,
                     measured / base[mask].mean(), both["3.x"] / base[mask].mean(),
                     both["4.x"] / base[mask].mean()), flush=True)
            label = "spot size %.0f blend %.2f, %g-%g deg" % (math.degrees(spot_size), spot_blend, lo, hi)
            if predicted[mask].mean() > 0.05 * axis_value:
                self.compare(label, pixels, predicted, mask)
            else:
                self.compare(label, pixels, predicted, mask, scale=axis_value)
        remove(light.name)

    def test_spot(self):
        # 60 degrees, blend 0.3: the band of cos from cos 30 = 0.8660 to 0.9062 (25.0 deg)
        self.spot(math.radians(60.0), 0.3, 1.8, [(0, 2), (10, 18), (25.5, 26.5), (27, 28.5),
                                                 (29, 29.8), (31, 40)])
        # 90 degrees, blend 1: the band spans the whole cone (cos 0.7071 to 1)
        self.spot(math.radians(90.0), 1.0, 2.4, [(0, 2), (15, 20), (30, 32), (40, 44), (46, 50)])
        # blend 0: a step at 30 degrees
        self.spot(math.radians(60.0), 0.0, 1.8, [(10, 18), (27, 29.7), (30.3, 40)])

    def test_spot_radius(self):
        self.near_point('SPOT', 0.25, 0.5, spot_size=math.radians(90.0), spot_blend=0.5)

    def test_spot_radius_hard_falloff(self):
        self.require('SPOT', "use_soft_falloff")
        self.near_point('SPOT', 0.25, 0.5, spot_size=math.radians(90.0), spot_blend=0.5,
                        use_soft_falloff=False)

    # --- sun and world --------------------------------------------------------------

    def sun(self, strength, colour, angle, tilt, **settings):
        light = self.light('SUN', (0, 0, 5), (tilt, 0, 0), energy=strength, color=colour,
                           angle=angle, **settings)
        self.view(0.0, 0.0, 1.0)
        pixels = self.render(64 if angle > 0 else 4)
        conv = light_units.sun_light(VERSION, strength, colour, angle,
                                     exposure=compat.light_exposure(light),
                                     normalize=compat.light_normalized(light))
        predicted = np.broadcast_to(conv["irradiance"] * math.cos(tilt), pixels.shape)
        mask = np.ones(pixels.shape[:2], dtype=bool)
        measured, _ = self.compare("sun %g angle %.3f tilt %.0f %s" % (
            strength, angle, math.degrees(tilt), settings or ""), pixels, predicted, mask)
        print("[measure] Blender %s, sun: H / (strength colour cos) = %s"
              % (bpy.app.version_string, np.round(measured / (strength * np.array(colour) * math.cos(tilt)), 5)),
              flush=True)
        remove(light.name)

    def test_sun(self):
        self.sun(3.0, (1.0, 0.5, 0.25), 0.0, 0.0)
        self.sun(1.5, (1.0, 1.0, 1.0), math.radians(10.0), 0.0)
        self.sun(1.5, (1.0, 1.0, 1.0), math.radians(10.0), math.radians(60.0))
        self.sun(2.0, (1.0, 1.0, 1.0), math.radians(90.0), math.radians(30.0))

    def test_world(self):
        colour, strength = (0.8, 0.4, 0.2), 1.5
        self.background.inputs[0].default_value = colour + (1.0,)
        self.background.inputs[1].default_value = strength
        try:
            self.view(0.0, 0.0, 1.0)
            pixels = self.render(16)
        finally:
            self.background.inputs[0].default_value = (0, 0, 0, 1)
            self.background.inputs[1].default_value = 1.0
        predicted = np.broadcast_to(light_units.world_radiance(colour, strength), pixels.shape)
        mask = np.ones(pixels.shape[:2], dtype=bool)
        self.compare("world (0.8, 0.4, 0.2) x 1.5, open plane", pixels, predicted, mask)

    # --- 4.x settings -----------------------------------------------------------------

    def point_setting(self, label, radius=0.0, **settings):
        power, height = 100.0, 1.0
        light = self.light('POINT', (0, 0, height), energy=power, radius=radius, **settings)
        x, y = self.view(0.0, 0.0, 0.5)
        pixels = self.render(4 if radius == 0 else 128)
        conv = light_units.point_light(VERSION, power, compat.light_colour(light), radius,
                                       exposure=compat.light_exposure(light),
                                       normalize=compat.light_normalized(light),
                                       soft_falloff=getattr(light, "use_soft_falloff", True))
        d, cos = self.point_geometry(x, y, height)
        predicted = light_units.point_light_h(conv["intensity"], radius, conv["shape"], d, cos)
        mask = np.ones(pixels.shape[:2], dtype=bool)
        remove(light.name)
        self.compare(label, pixels, predicted, mask, TOLERANCE if radius == 0 else NOISY_TOLERANCE)

    def test_exposure(self):
        self.require('POINT', "exposure")
        self.point_setting("point exposure 1.5", exposure=1.5)
        self.sun(2.0, (1, 1, 1), 0.0, 0.0, exposure=-1.0)

    def test_temperature(self):
        self.require('POINT', "use_temperature", "temperature")
        self.point_setting("point 3000 K", use_temperature=True, temperature=3000.0)

    def test_not_normalized(self):
        self.require('POINT', "normalize")
        self.point_setting("point r=0 normalize off", normalize=False)
        self.point_setting("point r=0.1 normalize off", radius=0.1, normalize=False)
        self.sun(2.0, (1, 1, 1), math.radians(10.0), 0.0, normalize=False)


if __name__ == "__main__":
    unittest.main()
