"""Game-ready colours and the glTF export of the result (issue 15), in each Blender.

The cube scene is solved twice, the default bake (HDR radiance, "Radiosity
Emission") and with Game-Ready Colours; the second is exported with
`radiosity.export_gltf` and the .glb is checked by the Khronos glTF validator
(tools/gltf_validator.py, which installs it into build/node when missing) and
read back: every mesh has COLOR_0 equal to the baked colours (within [0, 1])
and an unlit material, and no original object is in the file.
"""

import json
import os
import struct
import sys
import tempfile
import unittest
from pathlib import Path

import bpy
import numpy as np

import radiosity
from radiosity.model import display_colours
from radiosity.write import bake, game_ready, result_state

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "scenes")))
sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "tools")))
import build_scene  # noqa: E402
import gltf_validator  # noqa: E402

# build/addon/radiosity/__init__.py -> build
BUILD = Path(radiosity.__file__).resolve().parents[2]
TMP = tempfile.mkdtemp(prefix="radiosity-gltf-")
LIGHT = 12.0  # the cube scene's light radiance (scenes/cube.py)


def open_cube():
    path = os.path.join(TMP, "cube.blend")
    if not os.path.exists(path):
        bpy.ops.wm.read_homefile(use_empty=True)
        build_scene.build("cube", bpy.context.scene)
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    scene = bpy.context.scene
    # Coarse and quick: the export, not the solution, is under test.
    scene.radiosity.quality = 0.3
    return scene


def attribute(obj):
    attr = obj.data.color_attributes["Radiosity"]
    values = np.empty(4 * len(attr.data), dtype=np.float32)
    attr.data.foreach_get("color", values)
    return values.reshape(-1, 4)[:, :3]


def positions(obj):
    co = np.empty(3 * len(obj.data.vertices))
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def solve(scene):
    """Solve; the result objects by the names of their originals."""
    result = bpy.ops.radiosity.solve()
    assert result == {'FINISHED'}, result
    return {o[result_state.RESULT_TAG]: o for o in result_state.result_objects(scene)}


# --- Reading a .glb ------------------------------------------------------------------------

COMPONENTS = {5120: np.int8, 5121: np.uint8, 5122: np.int16, 5123: np.uint16, 5125: np.uint32, 5126: np.float32}
SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}


def read_glb(path):
    """(json, binary chunk) of a .glb."""
    data = Path(path).read_bytes()
    magic, version, _ = struct.unpack_from("<III", data, 0)
    assert magic == 0x46546C67 and version == 2
    length, kind = struct.unpack_from("<II", data, 12)
    assert kind == 0x4E4F534A  # JSON
    gltf = json.loads(data[20:20 + length])
    offset = 20 + length
    binary = b""
    if offset < len(data):
        blength, bkind = struct.unpack_from("<II", data, offset)
        assert bkind == 0x004E4942  # BIN
        binary = data[offset + 8:offset + 8 + blength]
    return gltf, binary


def accessor(gltf, binary, index):
    """An accessor's values as an (N, components) float array (normalized integers scaled to [0, 1])."""
    acc = gltf["accessors"][index]
    view = gltf["bufferViews"][acc["bufferView"]]
    dtype = np.dtype(COMPONENTS[acc["componentType"]])
    n = SIZES[acc["type"]]
    stride = view.get("byteStride", dtype.itemsize * n)
    start = view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    raw = np.frombuffer(binary, dtype=np.uint8, count=stride * (acc["count"] - 1) + dtype.itemsize * n,
                        offset=start)
    rows = np.lib.stride_tricks.as_strided(raw, shape=(acc["count"], dtype.itemsize * n), strides=(stride, 1))
    values = np.ascontiguousarray(rows).view(dtype).reshape(acc["count"], n).astype(np.float64)
    if acc.get("normalized") and dtype != np.float32:
        values /= np.iinfo(dtype).max
    return values


def colours_at(obj, points, tolerance):
    """For each glTF point (Y up), the baked colours of the object's vertices there (Z up)."""
    zup = np.column_stack([points[:, 0], -points[:, 2], points[:, 1]])
    co, values = positions(obj), attribute(obj)
    found = []
    for p in zup:
        near = np.linalg.norm(co - p, axis=1) <= tolerance
        found.append(values[near])
    return found


class GameReadyBakeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        scene = open_cube()
        cls.default = {name: (positions(o), attribute(o), [m.name for m in o.data.materials])
                       for name, o in solve(scene).items()}
        cls.default_warning = scene.radiosity.stats.warning

    def test_default_bake_is_unchanged(self):
        # Off by default; the bake holds the radiance (the light's 12, more than 1)
        # and the emission material, as before game-ready colours existed.
        scene = open_cube()
        self.assertFalse(scene.radiosity.display_colours)
        self.assertEqual(scene.radiosity.display_exposure, 0.0)
        for name, (co, values, materials) in self.default.items():
            self.assertEqual(materials, [bake.MATERIAL_NAME], name)
        np.testing.assert_allclose(self.default["Light"][1], LIGHT, rtol=1e-5)
        self.assertFalse(any(m.get(game_ready.UNLIT_TAG) for m in bpy.data.materials))

    def test_game_ready_colours_are_the_display_colours(self):
        for exposure in (0.0, -1.5):
            with self.subTest(exposure=exposure):
                scene = open_cube()
                scene.radiosity.display_colours = True
                scene.radiosity.display_exposure = exposure
                out = solve(scene)
                self.assertEqual(set(out), set(self.default))
                settings = display_colours.DisplaySettings(exposure=exposure)
                for name, obj in out.items():
                    co, radiance, _ = self.default[name]
                    # The same solve: the same mesh, its colours converted.
                    np.testing.assert_allclose(positions(obj), co, atol=1e-6)
                    values = attribute(obj)
                    np.testing.assert_allclose(values, display_colours.game_colours(radiance, settings),
                                               atol=1e-6, err_msg=name)
                    self.assertTrue(np.all((values >= 0.0) & (values <= 1.0)), name)
                    self.assertEqual([m.name for m in obj.data.materials], [game_ready.UNLIT_MATERIAL_NAME])
                    self.assertTrue(obj.data.materials[0].use_backface_culling)
                # Standard view: exposed radiance clamped, so the light is white at 0 and
                # at -1.5 stops (12 x 2^-1.5 = 4.2).
                np.testing.assert_allclose(attribute(out["Light"]), 1.0, atol=1e-6)
                self.assertEqual(scene.radiosity.stats.warning, self.default_warning)

    def test_scene_view_transform_and_exposure(self):
        scene = open_cube()
        scene.radiosity.display_colours = True
        scene.view_settings.view_transform = 'Filmic'
        scene.view_settings.exposure = 0.5
        out = solve(scene)
        settings, note = game_ready.display_settings(scene)
        self.assertEqual(settings.exposure, 0.5)
        if game_ready.import_ocio():
            # OpenColorIO (4.5, 5.0): Filmic's curve, not the Standard one.
            self.assertEqual(note, "")
            self.assertIsNotNone(settings.transform)
            floor = self.default["Floor"][1]
            standard = display_colours.game_colours(floor, display_colours.DisplaySettings(exposure=0.5))
            filmic = attribute(out["Floor"])
            self.assertGreater(np.abs(filmic - standard).max(), 0.02)
            np.testing.assert_allclose(filmic, display_colours.game_colours(floor, settings), atol=1e-5)
            # Filmic leaves a light of 12 x 2^0.5 below white... barely: it is bright.
            self.assertGreater(attribute(out["Light"]).min(), 0.8)
        else:
            # Without OpenColorIO (Debian's 3.4): Standard, and the warning says so.
            self.assertIn("Standard view transform instead of 'Filmic'", scene.radiosity.stats.warning)
            np.testing.assert_allclose(attribute(out["Floor"]), display_colours.game_colours(
                self.default["Floor"][1], display_colours.DisplaySettings(exposure=0.5)), atol=1e-6)

    def test_original_output_is_converted_too(self):
        scene = open_cube()
        scene.radiosity.display_colours = True
        scene.radiosity.output = 'ORIGINAL'
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        attr = scene.objects["Light"].data.color_attributes["Radiosity"]
        values = np.empty(4 * len(attr.data), dtype=np.float32)
        attr.data.foreach_get("color", values)
        np.testing.assert_allclose(values.reshape(-1, 4)[:, :3], 1.0, atol=1e-6)


class GltfExportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        scene = open_cube()
        scene.radiosity.display_colours = True
        cls.results = {o.name: o for o in solve(scene).values()}
        cls.originals = sorted({o.name for o in scene.objects if not o.get(result_state.RESULT_TAG)})
        # Something selected and active beforehand, to be given back.
        cube = scene.objects["Cube"]
        cube.hide_set(False)
        cube.select_set(True)
        bpy.context.view_layer.objects.active = cube
        cls.path = os.path.join(TMP, "cube.glb")
        cls.export_result = bpy.ops.radiosity.export_gltf(filepath=cls.path)
        cls.selected_after = sorted(o.name for o in bpy.context.view_layer.objects if o.select_get())
        cls.active_after = bpy.context.view_layer.objects.active
        cls.gltf, cls.binary = read_glb(cls.path)
        cls.report = gltf_validator.validate(BUILD, cls.path)
        print("glTF validator (Blender %s): %s" % (bpy.app.version_string, gltf_validator.summary(cls.report)))

    def test_exported_and_selection_restored(self):
        self.assertEqual(self.export_result, {'FINISHED'})
        self.assertEqual(self.selected_after, ["Cube"])
        self.assertEqual(self.active_after.name, "Cube")

    def test_glb_added_to_a_name_without_extension(self):
        path = os.path.join(TMP, "level")
        self.assertEqual(bpy.ops.radiosity.export_gltf(filepath=path), {'FINISHED'})
        self.assertTrue(os.path.isfile(path + ".glb"))
        self.assertEqual(read_glb(path + ".glb")[0]["nodes"], self.gltf["nodes"])

    def test_validator_finds_no_error(self):
        issues = self.report["issues"]
        errors = [m for m in issues["messages"] if m["severity"] == 0]
        self.assertEqual(issues["numErrors"], 0, json.dumps(errors[:10], indent=1))
        self.assertEqual(self.report["info"]["extensionsUsed"], ["KHR_materials_unlit"])

    def test_only_the_result_objects(self):
        names = sorted(n["name"] for n in self.gltf["nodes"])
        self.assertEqual(names, sorted(self.results))
        self.assertFalse(set(names) & set(self.originals))
        self.assertEqual(len(self.gltf["meshes"]), len(self.results))
        self.assertNotIn("cameras", self.gltf)
        self.assertNotIn("KHR_lights_punctual", self.gltf.get("extensionsUsed", []))

    def test_unlit_opaque_one_sided_material(self):
        for mesh in self.gltf["meshes"]:
            for prim in mesh["primitives"]:
                material = self.gltf["materials"][prim["material"]]
                self.assertIn("KHR_materials_unlit", material.get("extensions", {}), mesh["name"])
                self.assertEqual(material.get("alphaMode", "OPAQUE"), "OPAQUE")
                self.assertFalse(material.get("doubleSided", False))
                # The colour comes from COLOR_0 alone: the base colour stays white.
                pbr = material.get("pbrMetallicRoughness", {})
                self.assertEqual(pbr.get("baseColorFactor", [1, 1, 1, 1]), [1, 1, 1, 1])
                self.assertNotIn("baseColorTexture", pbr)
                self.assertNotIn("emissiveFactor", material)

    def test_color_0_is_the_baked_colours(self):
        nodes = {n["mesh"]: n for n in self.gltf["nodes"] if "mesh" in n}
        for index, mesh in enumerate(self.gltf["meshes"]):
            obj = self.results[nodes[index]["name"]]
            self.assertNotIn("translation", nodes[index])
            for prim in mesh["primitives"]:
                self.assertIn("COLOR_0", prim["attributes"], mesh["name"])
                self.assertFalse([a for a in prim["attributes"] if a.startswith("_")], mesh["name"])
                colour = accessor(self.gltf, self.binary, prim["attributes"]["COLOR_0"])[:, :3]
                self.assertTrue(np.all((colour >= 0.0) & (colour <= 1.0)), mesh["name"])
                points = accessor(self.gltf, self.binary, prim["attributes"]["POSITION"])
                for c, baked in zip(colour, colours_at(obj, points, 1e-5)):
                    self.assertGreater(len(baked), 0, mesh["name"])
                    self.assertLess(np.abs(baked - c).max(axis=1).min(), 1e-4, mesh["name"])

    def test_the_light_is_white(self):
        mesh = next(m for m in self.gltf["meshes"] if m["name"].startswith("Light"))
        colour = accessor(self.gltf, self.binary, mesh["primitives"][0]["attributes"]["COLOR_0"])
        np.testing.assert_allclose(colour[:, :3], 1.0, atol=1e-4)


class ExportRefusalTest(unittest.TestCase):
    def test_hdr_result_is_not_exported(self):
        scene = open_cube()
        solve(scene)
        path = os.path.join(TMP, "hdr.glb")
        with self.assertRaises(RuntimeError) as ctx:
            bpy.ops.radiosity.export_gltf(filepath=path)
        self.assertIn("Game-Ready Colours", str(ctx.exception))
        self.assertFalse(os.path.exists(path))

    def test_hdr_result_is_refused_before_the_file_browser(self):
        # Invoked from File > Export or the panel: refused with the same message
        # before the file browser opens (ExportHelper.invoke), not after a file
        # was chosen. Background Blender runs 'INVOKE_DEFAULT' as execute (it
        # has no window), so invoke is called as the window would call it.
        from bpy_extras.io_utils import ExportHelper
        from radiosity.write import gltf_export
        scene = open_cube()
        solve(scene)
        self.assertTrue(bpy.ops.radiosity.export_gltf.poll())
        reports, browsed = [], []

        class Invoked:
            def report(self, kinds, message):
                reports.append((kinds, message))

        opens_the_browser = ExportHelper.invoke
        ExportHelper.invoke = lambda op, context, event: browsed.append(op) or {'RUNNING_MODAL'}
        try:
            result = gltf_export.RADIOSITY_OT_export_gltf.invoke(Invoked(), bpy.context, None)
        finally:
            ExportHelper.invoke = opens_the_browser
        self.assertEqual(result, {'CANCELLED'})
        self.assertEqual(browsed, [])
        self.assertEqual(len(reports), 1)
        self.assertEqual(reports[0][0], {'ERROR'})
        self.assertIn("Game-Ready Colours", reports[0][1])

    def test_no_result_no_export(self):
        open_cube()
        self.assertFalse(bpy.ops.radiosity.export_gltf.poll())


class ViewTransformTest(unittest.TestCase):
    """The game-ready colours of a non-Standard view are what Blender shows: a Cycles
    render of emitting planes through Filmic, with exposure, a look and gamma, saved
    as an 8-bit PNG, against display_encoded of the same radiance."""

    RADIANCE = np.array([[0.05, 0.5, 3.0], [0.18, 0.18, 0.18], [8.0, 1.0, 0.01]])

    def render(self, scene):
        scene.render.engine = 'CYCLES'
        scene.cycles.device = 'CPU'
        scene.cycles.samples = 1
        scene.cycles.use_denoising = False
        scene.render.resolution_x, scene.render.resolution_y = 30, 10
        scene.render.resolution_percentage = 100
        scene.render.dither_intensity = 0.0
        scene.render.image_settings.file_format = 'PNG'
        scene.render.image_settings.color_depth = '8'
        path = os.path.join(TMP, "view.png")
        scene.render.filepath = path
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(write_still=True, scene=scene.name)
        image = bpy.data.images.load(path)
        image.colorspace_settings.name = 'Non-Color'
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        return pixels.reshape(10, 30, 4)[5, [5, 15, 25], :3]

    def test_filmic_look_exposure_gamma_match_a_render(self):
        if not game_ready.import_ocio():
            self.skipTest("no PyOpenColorIO in this Blender: game-ready colours use Standard")
        bpy.ops.wm.read_homefile(use_empty=True)
        scene = bpy.context.scene
        scene.world = None
        camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
        camera.data.type = 'ORTHO'
        camera.data.ortho_scale = 3.0
        camera.location = (0.0, 0.0, 5.0)
        scene.collection.objects.link(camera)
        scene.camera = camera
        for i, colour in enumerate(self.RADIANCE):
            mesh = bpy.data.meshes.new("Plane%d" % i)
            x = i - 1.0
            mesh.from_pydata([(x - 0.5, -1, 0), (x + 0.5, -1, 0), (x + 0.5, 1, 0), (x - 0.5, 1, 0)], [], [(0, 1, 2, 3)])
            material = bpy.data.materials.new("Emit%d" % i)
            material.use_nodes = True
            nodes = material.node_tree.nodes
            nodes.clear()
            emission = nodes.new("ShaderNodeEmission")
            emission.inputs["Color"].default_value = (*colour, 1.0)
            emission.inputs["Strength"].default_value = 1.0
            output = nodes.new("ShaderNodeOutputMaterial")
            material.node_tree.links.new(emission.outputs[0], output.inputs["Surface"])
            mesh.materials.append(material)
            scene.collection.objects.link(bpy.data.objects.new("Plane%d" % i, mesh))
        view = scene.view_settings
        view.view_transform = 'Filmic'
        view.exposure = 0.5
        view.gamma = 1.2
        for look in ("Medium High Contrast", "Filmic - Medium High Contrast"):  # 4.x, 3.x names
            try:
                view.look = look
                break
            except TypeError:
                continue
        self.assertIn("Medium High Contrast", view.look)
        rendered = self.render(scene)
        settings, note = game_ready.display_settings(scene)
        self.assertEqual(note, "")
        expected = display_colours.display_encoded(self.RADIANCE, settings)
        print("rendered", rendered.round(4).tolist(), "expected", expected.round(4).tolist())
        np.testing.assert_allclose(rendered, expected, atol=2.5 / 255)


if __name__ == "__main__":
    unittest.main()
