"""Blender's area-light power-to-radiance conversion, measured in Cycles and checked
against what the add-on exports (addon/read/export.py, arrays.area_light_radiance).

A white Diffuse BSDF plane 1 m under the light, direct light only, 64 x 64 pixels,
256 samples, an orthographic camera between them looking down. The mean of the
centre pixels under an area light is compared, per colour channel, with the same
under an emissive polygon of the light's shape and radiance 10, so the area
light's radiance is L = 10 x pixel_light / pixel_emissive. The test asserts that
this L is the radiance the export gives the light's polygon, within 1 %. The
factor L A / P ("[measure]" lines, run_tests -v) measured on this machine:

    Blender 3.4.1   square 0.2500, scaled rectangle 0.2500, disk 0.2504   (1/4)
    Blender 4.5.15  square 0.3183, scaled rectangle 0.3183, disk 0.3188   (1/pi = 0.31831)
    Blender 5.0.1   square 0.3183, scaled rectangle 0.3183, disk 0.3187

(the disk's reference is a 64-gon, 0.16 % smaller than the disk). In 4.5 and 5.0
also: exposure 1.5 gives 0.9003 = 2^1.5 / pi; normalize off, a 0.25 m square scaled
by 2 (A = 0.25) gives 0.0796 = A / pi, so L = P / pi, not divided by any area; a
3000 K temperature gives (0.5637, 0.2687, 0.0867) / (1/pi), the light's
temperature_color. Skipped where the light has no such setting (3.4).
"""

import math
import os
import tempfile
import unittest

import bpy
import numpy as np

from radiosity.read import export

RESOLUTION = 64
POWER = 10.0
REFERENCE_RADIANCE = 10.0
TOLERANCE = 0.01


def diffuse(name, value):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    node = nodes.new("ShaderNodeBsdfDiffuse")
    node.inputs["Color"].default_value = (value, value, value, 1.0)
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def emissive(name, radiance):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    node = nodes.new("ShaderNodeEmission")
    node.inputs["Strength"].default_value = radiance
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def add_mesh(scene, name, verts, material):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], [tuple(range(len(verts)))])
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    scene.collection.objects.link(obj)
    return obj


def outline(shape, size_x, size_y, z=1.0, sides=64):
    """The light's shape as a polygon at height z, facing down (-z)."""
    hx, hy = size_x / 2, size_y / 2
    if shape in ('SQUARE', 'RECTANGLE'):
        return [(-hx, -hy, z), (-hx, hy, z), (hx, hy, z), (hx, -hy, z)]
    angles = np.linspace(0.0, 2.0 * math.pi, sides, endpoint=False)
    return [(hx * math.cos(a), -hy * math.sin(a), z) for a in angles]


class AreaLightConversionTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        bpy.ops.wm.read_factory_settings(use_empty=True)
        scene = cls.scene = bpy.context.scene
        scene.render.engine = 'CYCLES'
        scene.cycles.device = 'CPU'
        scene.cycles.samples = 256
        scene.cycles.use_denoising = False
        scene.cycles.use_adaptive_sampling = False
        scene.cycles.max_bounces = 0   # direct light only
        scene.render.resolution_x = scene.render.resolution_y = RESOLUTION
        scene.view_settings.view_transform = 'Standard'
        scene.view_settings.look = 'None'
        world = bpy.data.worlds.new("Black")
        world.use_nodes = True
        world.node_tree.nodes["Background"].inputs[0].default_value = (0, 0, 0, 1)
        scene.world = world
        add_mesh(scene, "Plane", [(-2, -2, 0), (2, -2, 0), (2, 2, 0), (-2, 2, 0)], diffuse("White", 1.0))
        camera = bpy.data.cameras.new("Camera")
        camera.type = 'ORTHO'
        camera.ortho_scale = 1.0
        cam = bpy.data.objects.new("Camera", camera)
        cam.location = (0, 0, 0.9)
        scene.collection.objects.link(cam)
        scene.camera = cam
        cls.tmp = tempfile.TemporaryDirectory(prefix="radiosity-light-")
        cls.references = {}

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def render(self):
        """Mean linear RGB of the centre pixels."""
        scene = self.scene
        path = os.path.join(self.tmp.name, "measure.exr")
        scene.render.image_settings.file_format = 'OPEN_EXR'
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(path)
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        lo, hi = RESOLUTION * 3 // 8, RESOLUTION * 5 // 8
        return pixels.reshape(RESOLUTION, RESOLUTION, 4)[lo:hi, lo:hi, :3].reshape(-1, 3).mean(axis=0)

    def reference(self, shape, size_x, size_y):
        """Pixel under an emissive polygon of radiance 10 with the light's (scaled) shape."""
        key = (shape in ('DISK', 'ELLIPSE'), size_x, size_y)
        if key not in self.references:
            obj = add_mesh(self.scene, "Emitter", outline(shape, size_x, size_y),
                           emissive("Emitter", REFERENCE_RADIANCE))
            self.references[key] = self.render()
            bpy.data.objects.remove(obj)
        return self.references[key]

    def measure(self, shape, size, size_y=None, scale=(1, 1, 1), colour=(1, 1, 1), **settings):
        """(radiance measured in Cycles (rgb), radiance the add-on exports (rgb), world area)."""
        size_y = size if size_y is None else size_y
        light = bpy.data.lights.new("Area", 'AREA')
        light.shape, light.size, light.size_y = shape, size, size_y
        light.energy, light.color = POWER, colour
        for key, value in settings.items():
            setattr(light, key, value)
        obj = bpy.data.objects.new("Area", light)
        obj.location, obj.scale = (0, 0, 1), scale
        self.scene.collection.objects.link(obj)
        try:
            pixel = self.render()
            bpy.context.view_layer.update()
            exported = export.export_scene(bpy.context)
            part = [i for i, p in enumerate(exported.parts) if p.is_light]
            self.assertEqual(len(part), 1)
            rows = exported.arrays["face_part"] == part[0]
            emission = exported.arrays["emission"][rows][0]
        finally:
            bpy.data.objects.remove(obj)
            bpy.data.lights.remove(light)
        square = shape in ('SQUARE', 'DISK')
        world_x, world_y = size * scale[0], (size if square else size_y) * scale[1]
        measured = REFERENCE_RADIANCE * pixel / self.reference(shape, world_x, world_y)
        area = world_x * world_y * (math.pi / 4 if shape in ('DISK', 'ELLIPSE') else 1.0)
        return measured, emission, area

    def check(self, label, measured, exported, area):
        print("[measure] Blender %s, %s: L A / P = %s (exported %s)"
              % (bpy.app.version_string, label, np.round(measured * area / POWER, 5),
                 np.round(exported * area / POWER, 5)), flush=True)
        np.testing.assert_allclose(exported, measured, rtol=TOLERANCE, err_msg=label)

    def require(self, *names):
        missing = [n for n in names if not hasattr(bpy.types.Light, "bl_rna")
                   or n not in bpy.types.Light.bl_rna.properties]
        if missing:
            self.skipTest("Blender %s lights have no %s" % (bpy.app.version_string, ", ".join(missing)))

    def test_square(self):
        self.check("square 0.5", *self.measure('SQUARE', 0.5))

    def test_scaled_rectangle(self):
        self.check("rectangle 0.25 x 0.5, scale (2, 1, 1)",
                   *self.measure('RECTANGLE', 0.25, 0.5, scale=(2, 1, 1)))

    def test_disk(self):
        self.check("disk 0.5", *self.measure('DISK', 0.5))

    def test_colour(self):
        self.check("square 0.5, colour (1, 0.5, 0.25)", *self.measure('SQUARE', 0.5, colour=(1, 0.5, 0.25)))

    def test_exposure(self):
        self.require("exposure")
        self.check("square 0.5, exposure 1.5", *self.measure('SQUARE', 0.5, exposure=1.5))

    def test_not_normalized(self):
        self.require("normalize")
        self.check("square 0.25 scale (2, 2, 1), normalize off",
                   *self.measure('SQUARE', 0.25, scale=(2, 2, 1), normalize=False))

    def test_temperature(self):
        self.require("use_temperature", "temperature")
        self.check("square 0.5, 3000 K", *self.measure('SQUARE', 0.5, use_temperature=True, temperature=3000.0))


if __name__ == "__main__":
    unittest.main()
