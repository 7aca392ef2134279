"""Scene export (addon/read/export.py): what the solver is given for a Blender scene (headless).

Materials (Principled, Diffuse, Emission, Mix/Add, image-texture average,
unknown setups), modifiers and instances through the evaluated depsgraph,
world transforms including mirroring, area-light shapes and the warning for
what is not modelled.
"""

import math
import os
import sys
import unittest

import bpy
import numpy as np

from radiosity.model import arrays, findings
from radiosity.read import export
from radiosity.write import result_state

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "scenes")))
import scene_kit as kit  # noqa: E402

# L A / P of an area light, measured in Cycles (test_light_conversion.py).
AREA_LIGHT_FACTOR = 0.25 if bpy.app.version < (4, 0, 0) else 1.0 / math.pi


def new_file():
    bpy.ops.wm.read_homefile(use_empty=True)
    return bpy.context.scene


def plane(scene, name, material=None, location=(0, 0, 0), scale=(1, 1, 1)):
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    if material is not None:
        mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location, obj.scale = location, scale
    scene.collection.objects.link(obj)
    return obj


def node_material(name, build):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    shader = build(mat.node_tree)
    mat.node_tree.links.new(shader.outputs[0], out.inputs["Surface"])
    return mat


def export_now():
    bpy.context.view_layer.update()
    return export.export_scene(bpy.context)


def face_rows(exported, part_name):
    part = [p for p in exported.parts if p.name == part_name][0]
    i = exported.parts.index(part)
    rows = exported.arrays["face_part"] == i
    return {k: exported.arrays[k][rows] for k in ("reflectance", "emission", "two_sided")}


class MaterialTest(unittest.TestCase):
    def test_principled_diffuse_emission_mix(self):
        scene = new_file()

        def principled(tree):
            n = tree.nodes.new("ShaderNodeBsdfPrincipled")
            n.inputs["Base Color"].default_value = (0.2, 0.4, 0.6, 1)
            kit.principled_input(n, "Emission").default_value = (1.0, 0.5, 0.25, 1)
            n.inputs["Emission Strength"].default_value = 4.0
            return n

        def diffuse(tree):
            n = tree.nodes.new("ShaderNodeBsdfDiffuse")
            n.inputs["Color"].default_value = (0.3, 0.3, 0.1, 1)
            return n

        def emission(tree):
            n = tree.nodes.new("ShaderNodeEmission")
            n.inputs["Color"].default_value = (0.5, 1.0, 1.0, 1)
            n.inputs["Strength"].default_value = 3.0
            return n

        def mix(tree):
            m = tree.nodes.new("ShaderNodeMixShader")
            m.inputs["Fac"].default_value = 0.25
            tree.links.new(diffuse(tree).outputs[0], m.inputs[1])
            tree.links.new(emission(tree).outputs[0], m.inputs[2])
            return m

        def glossy(tree):
            return tree.nodes.new("ShaderNodeBsdfGlossy")

        for name, build in (("P", principled), ("D", diffuse), ("E", emission), ("M", mix), ("G", glossy)):
            plane(scene, name, node_material(name, build))
        bpy.data.materials["G"].diffuse_color = (0.1, 0.2, 0.3, 1)
        plane(scene, "None")
        ex = export_now()
        np.testing.assert_allclose(face_rows(ex, "P")["reflectance"], [[0.2, 0.4, 0.6]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "P")["emission"], [[4.0, 2.0, 1.0]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "D")["reflectance"], [[0.3, 0.3, 0.1]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "E")["emission"], [[1.5, 3.0, 3.0]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "E")["reflectance"], [[0, 0, 0]])
        np.testing.assert_allclose(face_rows(ex, "M")["reflectance"], [[0.225, 0.225, 0.075]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "M")["emission"], [[0.375, 0.75, 0.75]], rtol=1e-6)
        # Unknown setup: viewport colour, and said so.
        np.testing.assert_allclose(face_rows(ex, "G")["reflectance"], [[0.1, 0.2, 0.3]], rtol=1e-6)
        self.assertIn("materials G", findings.unmodelled_message(ex.unmodelled).replace("material ", "materials "))
        np.testing.assert_allclose(face_rows(ex, "None")["reflectance"], [export.DEFAULT_REFLECTANCE])
        self.assertTrue(np.all(ex.arrays["two_sided"]))

    def test_image_texture_average(self):
        scene = new_file()
        image = bpy.data.images.new("Checker", 4, 4, alpha=False, float_buffer=True)
        pixels = np.zeros((4, 4, 4), dtype=np.float32)
        pixels[..., 3] = 1
        pixels[:2, :, 0] = 0.8     # half red 0.8, half blue 0.4 (linear, float image)
        pixels[2:, :, 2] = 0.4
        image.pixels.foreach_set(pixels.ravel())

        def textured(tree):
            n = tree.nodes.new("ShaderNodeBsdfPrincipled")
            tex = tree.nodes.new("ShaderNodeTexImage")
            tex.image = image
            tree.links.new(tex.outputs["Color"], n.inputs["Base Color"])
            return n

        plane(scene, "T", node_material("T", textured))
        ex = export_now()
        np.testing.assert_allclose(face_rows(ex, "T")["reflectance"], [[0.4, 0.0, 0.2]], atol=1e-6)
        self.assertEqual(ex.unmodelled, [])   # a base colour texture is modelled (and kept: Lighting Only)

    def test_approximations_are_named(self):
        # Read as diffuse or averaged, and said so in the warning.
        scene = new_file()
        image = bpy.data.images.new("Screen", 2, 2, alpha=False, float_buffer=True)
        image.pixels.foreach_set(np.tile([2.0, 1.0, 0.5, 1.0], 4).astype(np.float32))

        def principled_with(name, value):
            def build(tree):
                n = tree.nodes.new("ShaderNodeBsdfPrincipled")
                n.inputs["Base Color"].default_value = (0.5, 0.5, 0.5, 1)
                kit.principled_input(n, name).default_value = value
                return n
            return build

        def screen(tree):
            n = tree.nodes.new("ShaderNodeEmission")
            tex = tree.nodes.new("ShaderNodeTexImage")
            tex.image = image
            tree.links.new(tex.outputs["Color"], n.inputs["Color"])
            return n

        plane(scene, "Metal", node_material("Metal", principled_with("Metallic", 1.0)))
        plane(scene, "Glass", node_material("Glass", principled_with("Transmission", 1.0)))
        plane(scene, "Screen", node_material("Screen", screen))
        ex = export_now()
        np.testing.assert_allclose(face_rows(ex, "Metal")["reflectance"], [[0.5, 0.5, 0.5]], rtol=1e-6)
        np.testing.assert_allclose(face_rows(ex, "Screen")["emission"], [[2.0, 1.0, 0.5]], rtol=1e-6)
        message = findings.unmodelled_message(ex.unmodelled)
        self.assertIn("material Metal (metallic read as diffuse)", message)
        self.assertIn("material Glass (transmission read as diffuse)", message)
        self.assertIn("material Screen (emission texture averaged)", message)


class GeometryTest(unittest.TestCase):
    def test_world_transform_modifiers_mirroring(self):
        scene = new_file()
        obj = plane(scene, "Arrayed", location=(0, 0, 2), scale=(-1, 1, 1))   # mirrored in x
        mod = obj.modifiers.new("Array", 'ARRAY')
        mod.count = 3
        ex = export_now()
        a = ex.arrays
        self.assertEqual(len(a["face_sizes"]), 3)
        self.assertTrue(np.all(a["face_sizes"] == 4))
        np.testing.assert_allclose(a["positions"][:, 2], 2.0)
        # The array goes along local +x, so world -x after the mirror.
        self.assertLess(a["positions"][:, 0].min(), -4.9)
        # Normals as Blender shows them: a plane's +z stays +z under the mirror.
        normals = arrays.polygon_normals(a["positions"], a["face_vertices"], a["face_sizes"])
        np.testing.assert_allclose(normals, [[0, 0, 1]] * 3, atol=1e-12)

    def test_collection_instances(self):
        scene = new_file()
        source = bpy.data.collections.new("Source")
        mesh_obj = bpy.data.objects.new("Thing", bpy.data.meshes.new("Thing"))
        mesh_obj.data.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
        source.objects.link(mesh_obj)
        for i in range(2):
            empty = bpy.data.objects.new("Instance.%d" % i, None)
            empty.instance_type = 'COLLECTION'
            empty.instance_collection = source
            empty.location = (5 * i, 0, 0)
            scene.collection.objects.link(empty)
        ex = export_now()
        self.assertEqual(len(ex.parts), 2)
        self.assertTrue(all(p.is_instance for p in ex.parts))
        self.assertEqual(sorted(p.source for p in ex.parts), ["Instance.0", "Instance.1"])
        self.assertEqual(sorted(ex.arrays["positions"][:, 0].max() for _ in [0]), [6.0])

    def test_hidden_and_result_objects_are_skipped(self):
        scene = new_file()
        plane(scene, "Shown")
        plane(scene, "NotRendered").hide_render = True
        plane(scene, "Result")[result_state.RESULT_TAG] = "Shown"
        self.assertEqual([p.name for p in export_now().parts], ["Shown"])


class LightTest(unittest.TestCase):
    def test_area_lights_and_warning(self):
        scene = new_file()
        for name, shape, size, size_y, scale in (("Rect", 'RECTANGLE', 0.5, 0.2, (2, 1, 1)),
                                                 ("Disk", 'DISK', 0.4, 0.4, (1, 1, 1)),
                                                 ("Ellipse", 'ELLIPSE', 0.4, 0.2, (1, 3, 1))):
            light = bpy.data.lights.new(name, 'AREA')
            light.shape, light.size, light.size_y, light.energy = shape, size, size_y, 100.0
            obj = bpy.data.objects.new(name, light)
            obj.scale = scale
            obj.rotation_euler = (math.radians(90), 0, 0)   # emits along +y
            scene.collection.objects.link(obj)
        for kind in ('POINT', 'SPOT', 'SUN', 'POINT'):
            scene.collection.objects.link(bpy.data.objects.new(kind, bpy.data.lights.new(kind, kind)))
        # Light node setups (IES too) are not modelled; the tree Blender 5.x gives
        # every new light (a white Emission of strength 1) changes nothing.
        default_tree = bpy.data.lights["POINT"]
        default_tree.use_nodes = True
        self.assertFalse(export.light_nodes_change_it(default_tree))
        self.assertEqual(findings.unmodelled_message(export_now().unmodelled), "")
        emission = next(n for n in default_tree.node_tree.nodes if n.bl_idname == 'ShaderNodeEmission')
        emission.inputs["Strength"].default_value = 2.0
        self.assertTrue(export.light_nodes_change_it(default_tree))
        ex = export_now()
        self.assertEqual(sorted(p.name for p in ex.parts), ["Disk", "Ellipse", "Rect"])
        a = ex.arrays
        self.assertFalse(np.any(a["two_sided"]))
        areas = {"Rect": 0.5 * 0.2 * 2, "Disk": math.pi * 0.04, "Ellipse": math.pi * 0.2 * 0.1 * 3}
        for i, part in enumerate(ex.parts):
            rows = np.flatnonzero(a["face_part"] == i)
            np.testing.assert_allclose(a["emission"][rows], [[AREA_LIGHT_FACTOR * 100 / areas[part.name]] * 3], rtol=1e-6)   # sizes are float32
            normal = arrays.polygon_normals(a["positions"], a["face_vertices"][
                np.repeat(a["face_part"], a["face_sizes"]) == i], a["face_sizes"][rows])
            np.testing.assert_allclose(normal, [[0, 1, 0]], atol=1e-6)   # -z turned to +y (float32 matrix)
        # Point, spot and sun lights are the solver's direct lights, not polygons.
        self.assertEqual(sorted(light["type"] for light in ex.lights), ["point", "point", "spot", "sun"])
        self.assertEqual(findings.unmodelled_message(ex.unmodelled), "Not modelled: light node setups")


if __name__ == "__main__":
    unittest.main()
