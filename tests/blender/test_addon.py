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
from radiosity.model import progress_text, quality_meaning
from radiosity.solve import native, pipeline
from radiosity.ui import operators, panels, properties
from radiosity.write import bake, result_state
from layout_check import DEFAULT_REGION_WIDTH, CheckedLayout, FakeContext, FakePanel, layout_width

# Every type the add-on registers, by its base type and RNA name.
ADDON_TYPES = (
    (bpy.types.PropertyGroup, "RadiosityStats"),
    (bpy.types.PropertyGroup, "RadiositySettings"),
    (bpy.types.Operator, "RADIOSITY_OT_solve"),
    (bpy.types.Operator, "RADIOSITY_OT_toggle_result"),
    (bpy.types.Operator, "RADIOSITY_OT_clear"),
    (bpy.types.Operator, "RADIOSITY_OT_export_gltf"),
    (bpy.types.Panel, "RENDER_PT_radiosity"),
    (bpy.types.Panel, "RENDER_PT_radiosity_quality"),
    (bpy.types.Panel, "RENDER_PT_radiosity_output"),
    (bpy.types.Panel, "RENDER_PT_radiosity_stats"),
    (bpy.types.Panel, "VIEW3D_PT_radiosity"),
    (bpy.types.Menu, "VIEW3D_MT_radiosity"),
)
PANELS = (panels.RENDER_PT_radiosity, panels.RENDER_PT_radiosity_quality, panels.RENDER_PT_radiosity_output,
          panels.RENDER_PT_radiosity_stats)
MENU_OPERATORS = ["radiosity.solve", "radiosity.toggle_result", "radiosity.clear"]
# What a running solve reports (operators.running_progress).
PROGRESS = {"fraction": 0.43, "pass": 2, "passes": 7, "leaves": 12316, "elements": 24631,
            "links": 402113, "seconds": 4.2, "phase": "pass"}


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


def draw_menu(name):
    """What the menu bpy.types.`name` draws (the record of a CheckedLayout), with
    the context of a 3D view (its View menu reads the space's settings)."""
    layout = CheckedLayout()
    context = FakeContext()
    context.space_data = next(s for screen in bpy.data.screens for a in screen.areas
                              for s in a.spaces if s.type == 'VIEW_3D')
    getattr(bpy.types, name).draw(FakePanel(layout), context)
    return layout.record


def menu_entries():
    """How often the Render menu holds Solve, the View menu the Radiosity menu and
    File > Export the glTF export."""
    return (draw_menu("TOPBAR_MT_render")["operators"].count("radiosity.solve"),
            draw_menu("VIEW3D_MT_view")["menus"].count("VIEW3D_MT_radiosity"),
            draw_menu("TOPBAR_MT_file_export")["operators"].count("radiosity.export_gltf"))


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
            self.assertEqual(menu_entries(), (0, 0, 0))
            self.assertFalse(hasattr(bpy.types.WindowManager, "radiosity_progress"))
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

    def test_disable_enable_twice_leaves_one_menu_entry(self):
        self.assertEqual(menu_entries(), (1, 1, 1))
        radiosity.unregister()
        try:
            for _ in range(2):
                addon_utils.enable("radiosity", default_set=False, handle_error=self._raise)
                self.assertEqual(menu_entries(), (1, 1, 1))
                addon_utils.disable("radiosity", default_set=False, handle_error=self._raise)
                self.assertEqual(menu_entries(), (0, 0, 0))
        finally:
            radiosity.register()
        self.assertEqual(menu_entries(), (1, 1, 1))
        # A second register without unregister (a script's) adds no second entry either.
        panels.register()
        self.assertEqual(menu_entries(), (1, 1, 1))

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

    def test_documentation_and_tracker(self):
        # No project site: the repository's README (a placeholder address) and its issues.
        repository = "https://github.com/radiosity-for-blender/radiosity"
        self.assertTrue(radiosity.bl_info["doc_url"].startswith(repository + "#"))
        self.assertEqual(radiosity.bl_info["tracker_url"], repository + "/issues")
        manifest_path = os.path.join(os.path.dirname(radiosity.__file__), "blender_manifest.toml")
        with open(manifest_path, "rb") as f:
            self.assertEqual(tomllib.load(f)["website"], radiosity.bl_info["doc_url"])


class DefaultsTest(unittest.TestCase):
    def setUp(self):
        self.settings = bpy.data.scenes.new("defaults").radiosity

    def tearDown(self):
        bpy.data.scenes.remove(self.settings.id_data)

    def test_enum_identifiers(self):
        # Written out: the identifiers are the scripting interface, which does not change.
        rna = self.settings.bl_rna.properties
        self.assertEqual(list(rna["oracle"].enum_items.keys()),
                         ["STANDARD", "PERCEPTUAL", "GRADIENT", "NOTICEABLE"])
        self.assertEqual(list(rna["visibility"].enum_items.keys()), ["EXACT", "SAMPLED"])
        self.assertIn("REFINED", rna["output"].enum_items)
        self.assertIn("ORIGINAL", rna["output"].enum_items)

    def test_defaults(self):
        s = self.settings
        self.assertEqual(s.oracle, 'NOTICEABLE')  # solve.h: the fastest to a given error
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

    def test_iterations_cannot_be_read_as_cycles_bounces(self):
        # The identifier scripts use stays; the UI name and tooltip say what it is.
        rna = self.settings.bl_rna.properties["bounces"]
        self.assertNotIn("Bounce", rna.name)
        self.assertIn("Not Cycles' light bounces", rna.description)
        self.assertIn("0 (the default) repeats until the lighting has converged", rna.description)

    def test_tooltips_speak_of_the_picture(self):
        # The oracles' algorithm names come last, after what they do to the picture.
        for item in self.settings.bl_rna.properties["oracle"].enum_items:
            self.assertTrue(item.description.startswith("Adds detail"), item.identifier)
        standard = self.settings.bl_rna.properties["oracle"].enum_items["STANDARD"].description
        self.assertLess(standard.index("time"), standard.index("BF refinement"))

    def test_limits_are_enforced(self):
        s = self.settings
        s.quality, s.rays, s.max_elements, s.time_budget = 7.0, 0, -5, -1.0
        self.assertEqual((s.quality, s.rays, s.max_elements, s.time_budget), (1.0, 1, 0, 0.0))
        with self.assertRaises(TypeError):
            s.oracle = 'BOGUS'

    def test_solver_options_are_plain_values(self):
        options = self.settings.solver_options()
        self.assertEqual(options["oracle"], "noticeable")
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
    def draw(self, panel=panels.RENDER_PT_radiosity, width=DEFAULT_REGION_WIDTH, layout=None):
        """Draw `panel` as in a Properties region `width` wide; return its layout."""
        layout = layout or CheckedLayout()
        panel.draw(FakePanel(layout), FakeContext(width))
        return layout

    def assert_fits(self, layout, width=DEFAULT_REGION_WIDTH):
        self.assertEqual(layout.overflows(layout_width(width)), [],
                         "(text, its width, room) cut at a region %d px wide" % width)

    def running(self, progress=PROGRESS):
        """A context in which operators.running_progress reports `progress`."""
        test = self

        class Running:
            def __enter__(self):
                self.saved = operators.running_progress
                operators.running_progress = lambda: None if progress is None else dict(progress)

            def __exit__(self, *exc):
                operators.running_progress = self.saved
                return False

        test.assertIsNone(operators.running_progress())  # no solve runs in these tests
        return Running()

    def test_poll(self):
        self.assertTrue(panels.RENDER_PT_radiosity.poll(bpy.context))
        for panel in PANELS:
            registered = getattr(bpy.types, panel.__name__)
            self.assertEqual((registered.bl_space_type, registered.bl_region_type, registered.bl_context),
                             ('PROPERTIES', 'WINDOW', "render"))

    def test_sub_panels(self):
        self.assertEqual(getattr(bpy.types.RENDER_PT_radiosity, "bl_parent_id", ""), "")
        children = {panel.bl_label: panel for panel in PANELS[1:]}
        self.assertEqual(list(children), ["Quality and Limits", "Output", "Statistics"])
        for panel in children.values():
            self.assertEqual(getattr(bpy.types, panel.__name__).bl_parent_id, "RENDER_PT_radiosity")
            # All open at first: the settings and the statistics are what the panel is for.
            self.assertNotIn('DEFAULT_CLOSED', getattr(panel, "bl_options", set()))

    def test_solve_button_first(self):
        layout = self.draw()
        self.assertEqual(layout.record["operators"], MENU_OPERATORS)
        # The parent's first row is the large Solve button.
        kind, column = layout._items[0]
        kind, row = column._items[0]
        self.assertEqual(row._items[0][1:3], ("button", "Solve Radiosity"))
        self.assertEqual(row.scale_y, 1.5)

    def test_draws_every_setting_once(self):
        drawn = []
        operators_drawn = []
        for panel in PANELS:
            record = self.draw(panel).record
            drawn += [name for data, name in record["props"] if isinstance(data, properties.RadiositySettings)]
            operators_drawn += record["operators"]
        # The add-on's own settings; `stats` is drawn as labels.
        settings = set(properties.RadiositySettings.__annotations__) - {"stats"}
        self.assertEqual(sorted(drawn), sorted(settings))
        self.assertEqual(operators_drawn, MENU_OPERATORS + ["radiosity.export_gltf"])
        self.assertIn("Not solved yet", self.draw(panels.RENDER_PT_radiosity_stats).record["labels"])

    def test_draws_last_solve_statistics(self):
        stats = bpy.context.scene.radiosity.stats
        stats.valid, stats.status, stats.oracle = True, "Converged", "Perceptual"
        stats.elements, stats.links, stats.iterations, stats.seconds = 12345, 67890, 4, 1.5
        stats.warning = "2 point lights not modelled"
        try:
            labels = self.draw(panels.RENDER_PT_radiosity_stats, width=600).record["labels"]
        finally:
            stats.clear()
        self.assertEqual(labels, ["Converged", "Oracle", "Perceptual", "Elements", "12,345", "Links", "67,890",
                                  "Iterations", "4", "Time", "1.50 s", "2 point lights not modelled"])

    def test_statistics_say_whether_the_solve_relit(self):
        stats = bpy.context.scene.radiosity.stats
        stats.valid, stats.status, stats.oracle = True, "Converged", "Perceptual"
        try:
            stats.relit = True
            relit = self.draw(panels.RENDER_PT_radiosity_stats).record["labels"]
            stats.relit, stats.relinked_because = False, "the geometry changed"
            layout = self.draw(panels.RENDER_PT_radiosity_stats)
        finally:
            stats.clear()
        # Wrapped to the panel's width: read as one text.
        self.assertIn("Relit: only the lighting had changed", " ".join(relit))
        self.assertIn("Linked anew: the geometry changed", " ".join(layout.record["labels"]))
        self.assert_fits(layout)

    def test_sidebar_tab_solves_and_sets_quality(self):
        # The 3D view's sidebar (N) has a Radiosity tab: Solve first, Toggle
        # and Remove, the oracle and quality with what the quality means.
        panel = bpy.types.VIEW3D_PT_radiosity
        self.assertEqual((panel.bl_space_type, panel.bl_region_type, panel.bl_category),
                         ('VIEW_3D', 'UI', "Radiosity"))
        self.assertTrue(panels.VIEW3D_PT_radiosity.poll(bpy.context))
        layout = self.draw(panels.VIEW3D_PT_radiosity)
        self.assertEqual(layout.record["operators"], MENU_OPERATORS)
        self.assertEqual([name for _, name in layout.record["props"]], ["oracle", "quality"])
        kind, column = layout._items[0]
        self.assertEqual(column._items[0][1]._items[0][1:3], ("button", "Solve Radiosity"))
        self.assert_fits(layout)

    def test_settings_at_zero_say_what_zero_means(self):
        settings = bpy.context.scene.radiosity
        limits = self.draw(panels.RENDER_PT_radiosity_quality, width=600).record["labels"]
        self.assertIn("Elements, Time Limit at 0: no limit. Min Size at 0: automatic. "
                      "Iterations at 0: until converged.", " ".join(limits))
        settings.max_elements, settings.bounces = 5000, 3
        try:
            limits = " ".join(self.draw(panels.RENDER_PT_radiosity_quality, width=600).record["labels"])
            self.assertIn("Time Limit at 0: no limit. Min Size at 0: automatic.", limits)
            self.assertNotIn("Elements", limits)
            self.assertNotIn("Iterations", limits)
        finally:
            settings.property_unset("max_elements")
            settings.property_unset("bounces")

    def test_no_links_say_why(self):
        stats = bpy.context.scene.radiosity.stats
        stats.valid, stats.status, stats.links = True, "Converged", 0
        try:
            layout = self.draw(panels.RENDER_PT_radiosity_stats)
            self.assertIn("None", layout.record["labels"])
            self.assertIn("No links: no two surfaces see each other, all light comes straight from the lights",
                          " ".join(layout.record["labels"]))
            self.assert_fits(layout)
            stats.status = "Time budget reached"
            labels = " ".join(self.draw(panels.RENDER_PT_radiosity_stats).record["labels"])
            self.assertIn("No links: the solve stopped before it linked any surfaces", labels)
        finally:
            stats.clear()

    def test_labels_fit_the_default_width(self):
        for panel in PANELS:
            with self.subTest(panel=panel.bl_label):
                self.assert_fits(self.draw(panel))

    def test_quality_reads_in_each_oracles_terms_and_fits(self):
        # The line under the slider states the threshold Quality sets, so it moves
        # with the slider, and the greyed lines under it what its number is; every
        # oracle's text and name fit the default width.
        settings = bpy.context.scene.radiosity
        saved = settings.oracle, settings.quality
        rad = native.load()
        try:
            for oracle in settings.bl_rna.properties["oracle"].enum_items.keys():
                settings.oracle = oracle
                texts = []
                for quality in (0.2, 0.8):
                    settings.quality = quality
                    threshold = rad.quality_threshold(oracle.lower(), quality)
                    texts.append(quality_meaning.quality_meaning(oracle, threshold))
                    with self.subTest(oracle=oracle, quality=quality):
                        layout = self.draw(panels.RENDER_PT_radiosity_quality)
                        self.assert_fits(layout)
                        headline, detail = texts[-1]
                        self.assertIn(headline, layout.record["labels"])
                        self.assertTrue(detail)
                        # The detail, wrapped, is there word for word.
                        labels = " ".join(layout.record["labels"])
                        self.assertIn(" ".join(detail.split()), labels)
                self.assertNotEqual(texts[0][0], texts[1][0], oracle)
            settings.quality = 0.0
            self.assertIn("No refinement: the coarsest lighting",
                          self.draw(panels.RENDER_PT_radiosity_quality).record["labels"])
        finally:
            settings.oracle, settings.quality = saved

    def test_quality_numbers_are_the_oracles_thresholds(self):
        # At the default quality (0.5) each threshold is the geometric mean of its
        # oracle's ends (solver.cpp, threshold_range) and each text says what it
        # allows the eye: per cent of the brightness, for Standard and Gradient on a
        # patch of 1 % of the scene's area (threshold / 0.01 and / 0.1), and for
        # Noticeable in JND and per cent (2 % a JND).
        rad = native.load()
        meaning = {oracle: quality_meaning.quality_meaning(oracle, rad.quality_threshold(oracle.lower(), 0.5))
                   for oracle in ('STANDARD', 'PERCEPTUAL', 'GRADIENT', 'NOTICEABLE')}
        self.assertAlmostEqual(rad.quality_threshold("standard", 0.5), 10 ** -4.5)  # 3.2e-5
        self.assertEqual(meaning['STANDARD'][0], "Light uneven below 0.32 %")
        self.assertIn("across a patch of 1 % of the area", meaning['STANDARD'][1])
        self.assertAlmostEqual(rad.quality_threshold("gradient", 0.5), 5e-3)
        self.assertEqual(meaning['GRADIENT'][0], "Light creases below 5.0 %")
        self.assertIn("over 1 % of the area", meaning['GRADIENT'][1])
        self.assertEqual(meaning['PERCEPTUAL'][0], "Shading errors below 6.3 %")
        self.assertAlmostEqual(rad.quality_threshold("noticeable", 0.5), 10 ** 0.5 / 2)  # 1.58 JND
        self.assertEqual(meaning['NOTICEABLE'],
                         ("Differences below 1.6 JND",
                          "about 3.2 % of the brightness around (1 JND, the least step seen: 2 %)"))
        # Larger or smaller numbers keep two digits and no exponent.
        self.assertEqual(quality_meaning.quality_meaning('STANDARD', 1e-7)[0], "Light uneven below 0.001 %")
        self.assertEqual(quality_meaning.quality_meaning('STANDARD', 1e-2)[0], "Light uneven below 100 %")

    def test_long_texts_are_wrapped_to_fit(self):
        stats = bpy.context.scene.radiosity.stats
        stats.valid, stats.status, stats.oracle = True, pipeline.STATUS["cancel"], "Gradient"
        stats.elements, stats.links, stats.iterations, stats.seconds = 1234567, 98765432, 40, 1234.5
        stats.warning = ("Not modelled: 2 point lights, 1 spot light (only area lights and emissive "
                         "surfaces are); faces left out: 3 degenerate faces of Chair.001")
        saved = native.advice
        native.advice = lambda: native.what_to_do(False)
        try:
            for width in (DEFAULT_REGION_WIDTH, 248, 400):
                for panel in (panels.RENDER_PT_radiosity, panels.RENDER_PT_radiosity_stats):
                    with self.subTest(panel=panel.bl_label, width=width):
                        layout = self.draw(panel, width)
                        self.assert_fits(layout, width)
            labels = self.draw(panels.RENDER_PT_radiosity_stats).record["labels"]
        finally:
            native.advice = saved
            stats.clear()
        self.assertEqual(" ".join(labels[:2]), pipeline.STATUS["cancel"])

    def test_the_checker_sees_what_was_cut(self):
        # The texts the issue found cut at the default width are cut by the checker's
        # measure too, and their replacements are not.
        settings = bpy.context.scene.radiosity
        layout = CheckedLayout()
        layout.use_property_split = True
        layout.prop(settings, "min_element_size", text="Smallest Element")
        layout.prop(settings, "min_element_size")
        row = layout.row(align=True)
        row.operator("radiosity.toggle_result", icon='HIDE_OFF')
        row.operator("radiosity.clear", icon='X')
        cut = [text for text, need, room in layout.overflows()]
        self.assertEqual(cut, ["Smallest Element", "Toggle Radiosity Result", "Remove Radiosity Result"])

    def test_progress_bar_while_solving(self):
        # Blender 4.0+ draws UILayout.progress; 3.4 has none, and CheckedLayout then has
        # none either (it knows only the running Blender's UILayout).
        with self.running():
            layout = self.draw(width=600)
        if "progress" in bpy.types.UILayout.bl_rna.functions:
            self.assertIn("Pass 3 of 7 · 12,316 elements · 4.2 s", layout.record["labels"])
            self.assertNotIn("12,316 elements", layout.record["labels"])
            self.assertNotIn((bpy.context.window_manager, "radiosity_progress"), layout.record["props"])
        else:
            self.assertIn((bpy.context.window_manager, "radiosity_progress"), layout.record["props"])
        self.assertIn("Esc to cancel", layout.record["labels"])
        self.assertIn(panels.SOLVING_LOCK, " ".join(layout.record["labels"]))
        self.assertEqual(layout.record["operators"][0], "radiosity.solve")

    def test_solve_toggle_and_remove_wait_while_a_solve_runs(self):
        bpy.ops.mesh.primitive_cube_add()
        bpy.context.active_object["radiosity_result"] = "Cube"  # a result to toggle and remove
        try:
            self.assertTrue(bpy.ops.radiosity.solve.poll())
            self.assertTrue(bpy.ops.radiosity.toggle_result.poll())
            self.assertTrue(bpy.ops.radiosity.clear.poll())
            operators._running_job = object()  # what an interactive solve sets while it runs
            try:
                for op in (bpy.ops.radiosity.solve, bpy.ops.radiosity.toggle_result, bpy.ops.radiosity.clear):
                    self.assertFalse(op.poll(), op)
            finally:
                operators._running_job = None
        finally:
            bpy.data.objects.remove(bpy.context.active_object)

    def test_fallback_bar_while_solving(self):
        class WithoutProgress(CheckedLayout):
            # A layout of a Blender before 4.0, also in 4.x.
            def __getattr__(self, name):
                if name == "progress":
                    raise AttributeError(name)
                return super().__getattr__(name)

        wm = bpy.context.window_manager
        with self.running():
            layout = self.draw(layout=WithoutProgress())
            value = wm.radiosity_progress
        self.assert_fits(layout)
        self.assertIn((wm, "radiosity_progress"), layout.record["props"])
        self.assertIn("12,316 elements", layout.record["labels"])
        self.assertAlmostEqual(value, 43.0, places=4)
        self.assertEqual(wm.radiosity_progress, 0.0)  # nothing runs now
        # The slider shows the text; dragging it changes nothing.
        wm.radiosity_progress = 90.0
        self.assertEqual(wm.radiosity_progress, 0.0)

    def test_progress_fits_the_default_width(self):
        for progress in (PROGRESS, {}, dict(PROGRESS, phase="linking", passes=0, fraction=0.02),
                         dict(PROGRESS, leaves=98765432, seconds=12345.6, passes=17, **{"pass": 16})):
            with self.subTest(progress=progress), self.running(progress):
                layout = self.draw()
                self.assert_fits(layout)
                labels = layout.record["labels"]
            if progress is PROGRESS:
                # Too long for one line here: the count goes below the bar.
                self.assertIn("12,316 elements", labels)
        self.assertEqual(progress_text.progress_texts({}), ("Starting", "Starting", ""))
        self.assertEqual(progress_text.progress_texts(PROGRESS), ("Pass 3 of 7 · 12,316 elements · 4.2 s",
                                                       "Pass 3 of 7 · 4.2 s", "12,316 elements"))
        self.assertEqual(progress_text.progress_texts(dict(PROGRESS, phase="linking", passes=0, leaves=0))[:2],
                         ("Preparing · 4.2 s", "Preparing · 4.2 s"))
        self.assertEqual(progress_text.progress_texts(dict(PROGRESS, seconds=3725.2))[1], "Pass 3 of 7 · 1:02:05")
        # `pass` counts from 0; after the last pass (phase done) it is the pass count.
        self.assertEqual(progress_text.progress_texts(dict(PROGRESS, phase="refining", **{"pass": 0}))[1], "Pass 1 of 7 · 4.2 s")
        self.assertEqual(progress_text.progress_texts(dict(PROGRESS, phase="done", **{"pass": 7}))[1], "Pass 7 of 7 · 4.2 s")
        # The status bar's line says the same, after the fraction.
        self.assertEqual(progress_text.status_line(PROGRESS),
                         "Radiosity: 43% · Pass 3 of 7 · 12,316 elements · 4.2 s")

    def test_warns_when_a_result_object_is_selected(self):
        mesh = bpy.data.meshes.new("result mesh")
        obj = bpy.data.objects.new("result", mesh)
        bpy.context.scene.collection.objects.link(obj)
        layer = bpy.context.view_layer
        active = layer.objects.active
        try:
            self.assertNotIn(panels.EDIT_WARNING, self.draw(width=600).record["labels"])
            obj[result_state.RESULT_TAG] = "Cube"
            self.assertNotIn(panels.EDIT_WARNING, self.draw(width=600).record["labels"])
            layer.objects.active = obj
            self.assertIn(panels.EDIT_WARNING, self.draw(width=600).record["labels"])
            layer.objects.active = active
            obj.select_set(True)
            self.assertIn(panels.EDIT_WARNING, self.draw(width=600).record["labels"])
            self.assert_fits(self.draw())
        finally:
            layer.objects.active = active
            bpy.data.objects.remove(obj)
            bpy.data.meshes.remove(mesh)

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


class MenuTest(unittest.TestCase):
    """Solve, Toggle and Remove in the Render menu and the 3D view's View > Radiosity,
    where F3 menu search finds them."""

    def test_render_menu(self):
        operators_drawn = draw_menu("TOPBAR_MT_render")["operators"]
        self.assertEqual([o for o in operators_drawn if o.startswith("radiosity.")], MENU_OPERATORS)
        self.assertEqual(operators_drawn[-3:], MENU_OPERATORS)  # after Blender's own

    def test_view_menu(self):
        record = draw_menu("VIEW3D_MT_view")
        self.assertEqual(record["menus"].count("VIEW3D_MT_radiosity"), 1)
        self.assertEqual(draw_menu("VIEW3D_MT_radiosity")["operators"], MENU_OPERATORS)
        self.assertEqual(bpy.types.VIEW3D_MT_radiosity.bl_label, "Radiosity")

    def test_operator_names_are_descriptive(self):
        # What F3 lists: the panel's buttons say less ("Toggle Result").
        names = [getattr(bpy.ops.radiosity, o.partition(".")[2]).get_rna_type().name for o in MENU_OPERATORS]
        self.assertEqual(names, ["Solve Radiosity", "Toggle Radiosity Result", "Remove Radiosity Result"])


class NativeMessageTest(unittest.TestCase):
    """What a user is told when the solver module does not load."""

    def test_source_build(self):
        package = os.path.dirname(radiosity.__file__)
        self.assertTrue(native.source_build(package))  # the tests run from BUILD/addon/radiosity
        with tempfile.TemporaryDirectory() as tmp:
            self.assertFalse(native.source_build(os.path.join(tmp, "addons", "radiosity")))
        advice = native.what_to_do(True)
        self.assertIn("rebuild the add-on with `make`", advice)

    def test_installed_zip(self):
        advice = native.what_to_do(False)
        self.assertNotIn("make", advice)
        version = ".".join(map(str, radiosity.bl_info["version"]))
        self.assertIn("radiosity-%s-linux_x64.zip, the same for every Blender from 3.4" % version, advice)
        self.assertNotIn("legacy", advice)
        self.assertIn("built for Linux x64 and Python 3.", advice)

    def test_panel_shows_what_to_do(self):
        saved = native.advice
        native.advice = lambda: native.what_to_do(False)
        try:
            labels = PanelTest.draw(None, width=4000).record["labels"]
        finally:
            native.advice = saved
        self.assertIn("Solver failed to load", labels)
        self.assertIn(native.what_to_do(False), labels)


class ResultObjectTest(unittest.TestCase):
    """The result objects are generated: not selectable, and marked so."""

    @classmethod
    def setUpClass(cls):
        # Solved in a scene file of its own; the factory scene the other tests use
        # is saved first and opened again after.
        from test_solve import open_scene  # here: test_solve imports this file
        cls.tmp = tempfile.TemporaryDirectory()
        cls.factory = os.path.join(cls.tmp.name, "factory.blend")
        bpy.ops.wm.save_as_mainfile(filepath=cls.factory, copy=True)
        scene = open_scene("cube")
        scene.radiosity.quality = 0.2
        cls.solved = bpy.ops.radiosity.solve()
        cls.results = [(o.name, o.hide_select, o.get(bake.GENERATED_NOTE_TAG))
                       for o in result_state.result_objects(scene)]
        cls.originals = [o.hide_select for o in scene.objects if not o.get(result_state.RESULT_TAG)]

    @classmethod
    def tearDownClass(cls):
        bpy.ops.wm.open_mainfile(filepath=cls.factory)
        cls.tmp.cleanup()

    def test_not_selectable_and_marked(self):
        self.assertEqual(self.solved, {'FINISHED'})
        self.assertGreater(len(self.results), 0)
        for name, hide_select, note in self.results:
            self.assertTrue(hide_select, name)
            self.assertIn("edits are replaced by the next Solve", note)
        self.assertFalse(any(self.originals))  # the user's objects are left as they were


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
