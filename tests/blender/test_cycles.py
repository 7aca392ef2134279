"""Agreement with Cycles (DESIGN.md section 3): a baked solution rendered through its
Emission material matches a path-traced Cycles render of the original scene.

Three scenes, all with Diffuse BSDF materials (Lambertian, like radiosity;
Cycles' Principled diffuse is not): the bundled cube room (emissive quad),
a room lit by a scaled rectangular area light (checks the measured
power-to-radiance conversion, L = P / (4 A) in Blender 3.x), and a room lit
by an emissive box made with the Principled BSDF's Emission (checks that
path of the material export). Same camera, Standard view transform, 96 x 72
pixels; the reference with enough samples that its region means are good to
about 1 %, the solution with 16 (it is noise-free but for anti-aliasing).

Tolerances (luminance, clipped at 1 as displayed): the image mean within 8 %
and every cell of a 4 x 3 grid within 12 % (relative to the cell, floored at a
tenth of the image mean). Measured on this machine (Blender 3.4.1, solver of
2026-12-01): cube -3.1 % mean, 4.2 % worst cell; area light -5.1 %, 7.0 %;
emissive mesh -4.4 %, 8.5 %. The solution comes out a little dark, growing
with the number of interreflection bounces (in the cube, direct light alone
agrees to 0.7 %, one bounce to 2.2 %, three to 5.9 %): reported to the solver.
Each test prints its numbers ("[agreement]" lines, shown with run_tests -v).
Renders of both sides are written to $RADIOSITY_TEST_IMAGES if set.
"""

import math
import os
import sys
import unittest

import bpy
import numpy as np

import render_compare as rc
from radiosity.write import result_state

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "scenes")))
import scene_kit as kit  # noqa: E402
from test_solve import open_scene  # noqa: E402

MEAN_TOLERANCE = 0.08
REGION_TOLERANCE = 0.12
REFERENCE_SAMPLES = 256
QUALITY = 0.8   # converged: higher quality changes these numbers by < 1 %


def diffuse_material(name, colour):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes = mat.node_tree.nodes
    nodes.clear()
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*colour, 1.0)
    out = nodes.new("ShaderNodeOutputMaterial")
    mat.node_tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    mat.diffuse_color = (*colour, 1.0)
    return mat


def small_room(scene):
    """A 3 x 3 x 2.5 m room (white walls, a red one, grey floor) with a box on the floor."""
    white = diffuse_material("White", (0.7, 0.7, 0.7))
    red = diffuse_material("Red", (0.6, 0.1, 0.08))
    floor = diffuse_material("Floor", (0.45, 0.42, 0.38))
    mats = {"Wall.Left": red, "Floor": floor}
    for name, geometry in kit.room_walls((-1.5, -1.5, 0.0), (1.5, 1.5, 2.5)).items():
        kit.add_mesh(scene, name, geometry, mats.get(name, white))
    kit.add_mesh(scene, "Box", kit.box((0.6, 0.6, 0.8), omit=("bottom",)), white,
                 location=(0.3, 0.4, 0.4), rotation=(0, 0, math.radians(30)))
    kit.add_camera(scene, location=(-0.4, -1.4, 1.5), target=(0.2, 0.4, 0.5), lens=18.0)
    kit.setup_render(scene)


class CyclesAgreementTest(unittest.TestCase):
    def agree(self, scene, label):
        reference = rc.render_image(scene, REFERENCE_SAMPLES)
        scene.radiosity.quality = QUALITY
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        self.assertTrue(result_state.result_objects(scene))
        solution = rc.render_image(scene, 16)
        folder = os.environ.get("RADIOSITY_TEST_IMAGES")
        if folder:
            os.makedirs(folder, exist_ok=True)
            rc.save_png(reference, os.path.join(folder, label + "_cycles.png"))
            rc.save_png(solution, os.path.join(folder, label + "_radiosity.png"))
        mean_error, region_error, ours, theirs = rc.compare(solution, reference)
        signed = rc.luminance(solution).mean() / rc.luminance(reference).mean() - 1
        print("[agreement] %s: mean %+.1f %%, worst cell %.1f %% (%d elements, %s)"
              % (label, 100 * signed, 100 * region_error, scene.radiosity.stats.elements,
                 scene.radiosity.stats.status), flush=True)
        print("[agreement] radiosity cells\n%s\n[agreement] cycles cells\n%s"
              % (np.round(ours, 3), np.round(theirs, 3)), flush=True)
        self.assertLess(mean_error, MEAN_TOLERANCE)
        self.assertLess(region_error, REGION_TOLERANCE)

    def test_cube(self):
        scene = open_scene("cube")
        for mat in bpy.data.materials:
            kit.make_lambertian(mat)
        self.agree(scene, "cube")

    def test_area_light(self):
        bpy.ops.wm.read_homefile(use_empty=True)
        scene = bpy.context.scene
        small_room(scene)
        light = bpy.data.lights.new("Area", 'AREA')
        light.shape = 'RECTANGLE'
        light.size, light.size_y = 0.6, 0.4
        light.energy = 40.0
        light.color = (1.0, 0.9, 0.8)
        obj = bpy.data.objects.new("Area", light)
        obj.location = (0.0, 0.0, 2.2)
        obj.scale = (1.5, 1.0, 1.0)    # the conversion must use the scaled area
        scene.collection.objects.link(obj)
        self.agree(scene, "area_light")
        # The light became a one-sided polygon of radiance P / (4 A) in 3.x, P / (pi A)
        # in 4.x and 5.x (measured: test_light_conversion.py).
        out = [o for o in result_state.result_objects(scene) if o["radiosity_result"] == "Area"][0]
        attr = out.data.color_attributes["Radiosity"]
        values = np.empty(4 * len(attr.data), dtype=np.float32)
        attr.data.foreach_get("color", values)
        factor = 0.25 if bpy.app.version < (4, 0, 0) else 1.0 / math.pi
        expected = factor * 40.0 / (0.6 * 1.5 * 0.4) * np.array([1.0, 0.9, 0.8])
        np.testing.assert_allclose(values.reshape(-1, 4)[:, :3], np.tile(expected, (len(attr.data), 1)), rtol=1e-5)

    def test_emissive_mesh(self):
        bpy.ops.wm.read_homefile(use_empty=True)
        scene = bpy.context.scene
        small_room(scene)
        lamp = bpy.data.materials.new("Lamp")
        lamp.use_nodes = True
        bsdf = lamp.node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        kit.principled_input(bsdf, "Specular").default_value = 0.0
        kit.principled_input(bsdf, "Emission").default_value = (0.9, 1.0, 0.8, 1.0)
        bsdf.inputs["Emission Strength"].default_value = 25.0
        kit.add_mesh(scene, "Lamp", kit.box((0.3, 0.3, 0.3)), lamp, location=(-0.5, 0.2, 1.9))
        self.agree(scene, "emissive_mesh")


if __name__ == "__main__":
    unittest.main()
