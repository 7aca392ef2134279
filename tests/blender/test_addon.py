"""The add-on registers, unregisters, draws and fails cleanly (headless Blender).

Run by tests/run_tests.py inside `blender --background --factory-startup` with
build/addon on sys.path and the add-on already registered.
"""

import json
import os
import tempfile
import tomllib
import unittest

import addon_utils
import bpy

import radiosity
from radiosity import native, operators, pipeline, properties, ui
from layout_check import CheckedLayout, FakePanel

# Every type the add-on registers, by its base type and RNA name.
ADDON_TYPES = (
    (bpy.types.PropertyGroup, "RadiosityStats"),
    (bpy.types.PropertyGroup, "RadiositySettings"),
    (bpy.types.Operator, "RADIOSITY_OT_solve"),
    (bpy.types.Operator, "RADIOSITY_OT_toggle_result"),
    (bpy.types.Operator, "RADIOSITY_OT_clear"),
    (bpy.types.Operator, "RADIOSITY_OT_export_gltf"),
    (bpy.types.Panel, "RENDER_PT_radiosity"),
)


def registered_type(base, name):
    """The registered Python class called `name` deriving from `base`, or None."""
    return base.bl_rna_get_subclass_py(name)


def operator_registered():
    try:
        bpy.ops.radiosity.solve.get_rna_type()
        return True
    except KeyError:
        return False


def scene_snapshot(scene):
    """What the solve operator could change, in comparable form."""
    data = {name: sorted(item.name for item in getattr(bpy.data, name))
            for name in ("objects", "meshes", "materials", "collections", "images",
                         "node_groups", "lights", "cameras", "worlds", "scenes")}
    data["attributes"] = {m.name: sorted(a.name for a in m.attributes) for m in bpy.data.meshes}
    data["hidden"] = {o.name: (o.hide_render, o.hide_viewport, o.hide_get()) for o in scene.objects}
    data["matrices"] = {o.name: [tuple(r) for r in o.matrix_world] for o in scene.objects}
    data["settings"] = settings_values(scene.radiosity)
    data["stats"] = settings_values(scene.radiosity.stats)
    return data


def settings_values(group):
    return {p.identifier: getattr(group, p.identifier) for p in group.bl_rna.properties
            if p.identifier != "rna_type" and p.type != 'POINTER'}


class RegistrationTest(unittest.TestCase):
    def test_registered(self):
        self.assertTrue(hasattr(bpy.types.Scene, "radiosity"))
        self.assertIsInstance(bpy.context.scene.radiosity, properties.RadiositySettings)
        self.assertTrue(operator_registered())
        for base, name in ADDON_TYPES:
            self.assertIsNotNone(registered_type(base, name), name)
        self.assertEqual(len(radiosity.classes), len(ADDON_TYPES))
        self.assertTrue(all(cls.is_registered for cls in radiosity.classes))

    def test_unregister_leaves_nothing_behind(self):
        radiosity.unregister()
        try:
            self.assertFalse(hasattr(bpy.types.Scene, "radiosity"))
            self.assertNotIn("radiosity", bpy.types.Scene.bl_rna.properties)
            self.assertFalse(hasattr(bpy.context.scene, "radiosity"))
            self.assertFalse(operator_registered())
            for base, name in ADDON_TYPES:
                self.assertIsNone(registered_type(base, name), name)
                self.assertFalse(hasattr(bpy.types, name), name)
            self.assertFalse(any(cls.is_registered for cls in radiosity.classes))
        finally:
            radiosity.register()
        # And it comes back whole after a second register.
        self.test_registered()

    def test_enable_through_addon_utils(self):
        # The path Preferences > Add-ons takes: checks bl_info, then registers.
        radiosity.unregister()
        try:
            module = addon_utils.enable("radiosity", default_set=False, handle_error=self._raise)
            self.assertIs(module, radiosity)
            self.assertTrue(operator_registered())
            addon_utils.disable("radiosity", default_set=False, handle_error=self._raise)
            self.assertFalse(operator_registered())
        finally:
            radiosity.register()

    @staticmethod
    def _raise(err):
        raise err

    def test_versions_agree(self):
        # bl_info (Blender 3.x), the extension manifest (4.2+) and the native module.
        manifest_path = os.path.join(os.path.dirname(radiosity.__file__), "blender_manifest.toml")
        with open(manifest_path, "rb") as f:
            manifest = tomllib.load(f)
        self.assertEqual(manifest["schema_version"], "1.0.0")
        self.assertEqual(manifest["id"], "radiosity")
        self.assertEqual(manifest["type"], "add-on")
        self.assertIn("linux-x64", manifest["platforms"])
        version = ".".join(map(str, radiosity.bl_info["version"]))
        self.assertEqual(manifest["version"], version)
        self.assertEqual(native.version(), version)
        self.assertLessEqual(tuple(radiosity.bl_info["blender"]), bpy.app.version)


class DefaultsTest(unittest.TestCase):
    def setUp(self):
        self.settings = bpy.data.scenes.new("defaults").radiosity

    def tearDown(self):
        bpy.data.scenes.remove(self.settings.id_data)

    def test_enum_identifiers(self):
        rna = self.settings.bl_rna.properties
        self.assertEqual(list(rna["oracle"].enum_items.keys()), ["STANDARD", "PERCEPTUAL", "GRADIENT"])
        self.assertEqual(list(rna["visibility"].enum_items.keys()), ["EXACT", "SAMPLED"])
        self.assertIn("REFINED", rna["output"].enum_items)
        self.assertIn("ORIGINAL", rna["output"].enum_items)

    def test_defaults(self):
        s = self.settings
        self.assertEqual(s.oracle, 'PERCEPTUAL')
        self.assertEqual(s.visibility, 'EXACT')
        self.assertEqual(s.rays, 16)
        self.assertEqual(s.bounces, 0)
        self.assertEqual(s.max_elements, 0)
        self.assertEqual(s.time_budget, 0.0)
        self.assertEqual(s.output, 'REFINED')
        self.assertFalse(s.show_wireframe)
        self.assertFalse(s.stats.valid)

    def test_defaults_are_the_solvers(self):
        """Each setting the solver also has starts at the solver's default (one definition, in C++)."""
        defaults = json.loads(native.load().DEFAULTS_JSON)
        s = self.settings
        self.assertEqual(s.oracle.lower(), defaults["oracle"])
        self.assertEqual(s.visibility.lower(), defaults["visibility"])
        self.assertAlmostEqual(s.quality, defaults["quality"], places=6)
        self.assertEqual(s.rays, defaults["rays"])
        self.assertEqual(s.bl_rna.properties["rays"].hard_max, defaults["max_rays"])

    def test_every_default_within_its_range(self):
        for group in (self.settings, self.settings.stats):
            for prop in group.bl_rna.properties:
                value = getattr(group, prop.identifier)
                if prop.type in {'INT', 'FLOAT'}:
                    self.assertTrue(prop.hard_min <= value <= prop.hard_max, prop.identifier)
                    self.assertTrue(prop.description, prop.identifier)
                elif prop.type == 'ENUM':
                    self.assertIn(value, prop.enum_items, prop.identifier)
                    for item in prop.enum_items:
                        self.assertTrue(item.description, item.identifier)

    def test_limits_are_enforced(self):
        s = self.settings
        s.quality, s.rays, s.max_elements, s.time_budget = 7.0, 0, -5, -1.0
        self.assertEqual((s.quality, s.rays, s.max_elements, s.time_budget), (1.0, 1, 0, 0.0))
        with self.assertRaises(TypeError):
            s.oracle = 'BOGUS'

    def test_solver_options_are_plain_values(self):
        options = self.settings.solver_options()
        self.assertEqual(options["oracle"], "perceptual")
        self.assertEqual(options["visibility"], "exact")
        for value in options.values():
            self.assertIsInstance(value, (int, float, str))

    def test_settings_survive_save_and_reload(self):
        scene = bpy.context.scene
        scene.radiosity.oracle = 'GRADIENT'
        scene.radiosity.rays = 64
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "settings.blend")
            bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
            scene.radiosity.property_unset("oracle")
            scene.radiosity.property_unset("rays")
            bpy.ops.wm.open_mainfile(filepath=path)
        # Opening a file replaced the data, so self.settings' scene is gone.
        self.settings = bpy.data.scenes.new("defaults").radiosity
        self.assertEqual(bpy.context.scene.radiosity.oracle, 'GRADIENT')
        self.assertEqual(bpy.context.scene.radiosity.rays, 64)


class PanelTest(unittest.TestCase):
    def draw(self):
        layout = CheckedLayout()
        ui.RENDER_PT_radiosity.draw(FakePanel(layout), bpy.context)
        return layout.record

    def test_poll(self):
        self.assertTrue(ui.RENDER_PT_radiosity.poll(bpy.context))
        panel = bpy.types.RENDER_PT_radiosity
        self.assertEqual((panel.bl_space_type, panel.bl_region_type, panel.bl_context),
                         ('PROPERTIES', 'WINDOW', "render"))

    def test_draws_every_setting_and_the_solve_button(self):
        record = self.draw()
        drawn = {name for data, name in record["props"] if isinstance(data, properties.RadiositySettings)}
        # The add-on's own settings; `stats` is drawn as labels.
        settings = set(properties.RadiositySettings.__annotations__) - {"stats"}
        self.assertEqual(drawn, settings)
        self.assertEqual(record["operators"], ["radiosity.solve", "radiosity.toggle_result", "radiosity.clear",
                                               "radiosity.export_gltf"])
        self.assertIn("Not solved yet", record["labels"])

    def test_draws_last_solve_statistics(self):
        stats = bpy.context.scene.radiosity.stats
        stats.valid, stats.status, stats.oracle = True, "Converged", "Perceptual"
        stats.elements, stats.links, stats.iterations, stats.seconds = 12345, 67890, 4, 1.5
        stats.warning = "2 point lights not modelled"
        try:
            labels = self.draw()["labels"]
        finally:
            stats.clear()
        self.assertIn("Last solve: Converged", labels)
        self.assertIn("Elements: 12,345   Links: 67,890", labels)
        self.assertIn("Iterations: 4   Time: 1.50 s", labels)
        self.assertIn("2 point lights not modelled", labels)

    def test_layout_check_is_strict(self):
        # The checker itself must catch what real drawing reports as errors.
        layout = CheckedLayout()
        settings = bpy.context.scene.radiosity
        with self.assertRaises(AttributeError):
            layout.prop(settings, "no_such_setting")
        with self.assertRaises(TypeError):
            layout.prop(settings, "rays", txt="typo")
        with self.assertRaises(AttributeError):
            layout.operator("radiosity.no_such_operator")
        with self.assertRaises(ValueError):
            layout.label(text="x", icon='NO_SUCH_ICON')
        with self.assertRaises(AttributeError):
            layout.use_property_splitt = True


class UnlitFactoryScene:
    """The factory scene (a cube, a point light, a grey world) with no light the
    solver models: the point light unlinked and the world's Background fed by a
    texture (only a uniform colour is modelled). Undone on exit, so every test
    sees the factory scene it started with and nothing here is ever solved."""

    def __enter__(self):
        scene = bpy.context.scene
        self.light = bpy.data.objects["Light"]
        self.collections = list(self.light.users_collection)
        for collection in self.collections:
            collection.objects.unlink(self.light)
        self.world = scene.world
        textured = bpy.data.worlds.new("Textured World")
        textured.use_nodes = True
        nodes = textured.node_tree.nodes
        background = next(n for n in nodes if n.type == 'BACKGROUND')
        noise = nodes.new("ShaderNodeTexNoise")
        textured.node_tree.links.new(noise.outputs["Color"], background.inputs["Color"])
        scene.world = textured
        return scene

    def __exit__(self, *exc):
        scene = bpy.context.scene
        textured, scene.world = scene.world, self.world
        bpy.data.worlds.remove(textured)
        for collection in self.collections:
            collection.objects.link(self.light)
        return False


class OperatorTest(unittest.TestCase):
    def setUp(self):
        self.unlit = UnlitFactoryScene()
        self.unlit.__enter__()

    def tearDown(self):
        self.unlit.__exit__(None, None, None)

    def solve_error(self, *args):
        """Run the operator; return the message Blender raises for its ERROR report."""
        with self.assertRaises(RuntimeError) as caught:
            bpy.ops.radiosity.solve(*args)
        message = str(caught.exception)
        # An exception escaping execute() would show up as "Python: Traceback ...".
        self.assertNotIn("Traceback", message)
        self.assertTrue(message.startswith("Error: "), message)
        return message

    def test_poll_in_object_mode(self):
        self.assertEqual(bpy.context.mode, 'OBJECT')
        self.assertTrue(bpy.ops.radiosity.solve.poll())

    def test_poll_fails_in_edit_mode(self):
        bpy.context.view_layer.objects.active = bpy.data.objects["Cube"]
        bpy.ops.object.mode_set(mode='EDIT')
        try:
            self.assertFalse(bpy.ops.radiosity.solve.poll())
        finally:
            bpy.ops.object.mode_set(mode='OBJECT')

    def test_reports_no_light_and_changes_nothing(self):
        # Nothing emits, no light, and the textured world is not modelled.
        # Blender turns an ERROR report of a cancelled operator into
        # RuntimeError for Python callers; the return value {'CANCELLED'} is
        # checked below.
        scene = bpy.context.scene
        before = scene_snapshot(scene)
        for context in ('EXEC_DEFAULT', 'INVOKE_DEFAULT'):
            message = self.solve_error(context)
            self.assertIn("No light to solve", message)
            # Says why the world does not count.
            self.assertIn("Not modelled: world Textured World (only a uniform Background colour", message)
            self.assertEqual(scene_snapshot(scene), before)

    def test_returns_cancelled(self):
        # Without a window there is no way to read the return value through
        # bpy.ops when an error is reported, so call the operator's method on a
        # stand-in that collects the report.
        reports = []

        class Stub:
            _conclude = operators.RADIOSITY_OT_solve._conclude
            _unexpected = operators.RADIOSITY_OT_solve._unexpected

            def report(self, kind, message):
                reports.append((kind, message))

        result = operators.RADIOSITY_OT_solve._run(Stub(), bpy.context)
        self.assertEqual(result, {'CANCELLED'})
        self.assertEqual(len(reports), 1)
        self.assertEqual(reports[0][0], {'ERROR'})
        self.assertIn("No light to solve", reports[0][1])

    def test_missing_native_module_is_reported(self):
        def unavailable():
            raise native.NativeUnavailable("Radiosity native module could not be loaded: test")

        saved = native.load
        native.load = unavailable
        try:
            message = self.solve_error()
        finally:
            native.load = saved
        self.assertIn("native module could not be loaded: test", message)

    def test_unexpected_exception_becomes_a_report(self):
        def broken(context, solver, started):
            raise ZeroDivisionError("simulated bug")

        saved = pipeline.prepare
        pipeline.prepare = broken
        try:
            message = self.solve_error()
        finally:
            pipeline.prepare = saved
        self.assertIn("failed unexpectedly: ZeroDivisionError: simulated bug", message)


if __name__ == "__main__":
    unittest.main()
