"""Solving bundled scenes through the operator, and what the bake leaves (headless Blender).

The cube scene is built once into a temporary .blend; each test opens it
fresh. Covers every oracle, the result meshes and their attribute, lit versus
shadowed surfaces, colour bleeding, re-solving, undo, clear/toggle, the
original-mesh output, errors that change nothing, cancelling (through the
same worker and conclude code the interactive path uses), and the command
line `blender -b file.blend --python-expr "...solve()"`.
"""

import os
import subprocess
import sys
import tempfile
import threading
import unittest

import bpy
import numpy as np

import radiosity
from radiosity.model import oracles
from radiosity.solve import native, pipeline, solve_reuse
from radiosity.ui import operators
from radiosity.write import bake, result_state

sys.path.insert(0, os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "scenes")))
import build_scene  # noqa: E402
import catalog  # noqa: E402
from test_addon import scene_snapshot  # noqa: E402

ADDON_DIR = os.path.dirname(os.path.dirname(os.path.abspath(radiosity.__file__)))  # build/addon
TMP = tempfile.mkdtemp(prefix="radiosity-test-")


def build_file(name):
    """Build scene `name` into TMP/name.blend (once) and return the path."""
    path = os.path.join(TMP, name + ".blend")
    if not os.path.exists(path):
        bpy.ops.wm.read_homefile(use_empty=True)
        scene = bpy.context.scene
        build_scene.build(name, scene)
        bpy.ops.wm.save_as_mainfile(filepath=path, copy=True)
    return path


def open_scene(name):
    bpy.ops.wm.open_mainfile(filepath=build_file(name))
    return bpy.context.scene


def attribute(obj):
    """(V, 3) values of the point-domain "Radiosity" attribute."""
    attr = obj.data.color_attributes["Radiosity"]
    values = np.empty(4 * len(attr.data), dtype=np.float32)
    attr.data.foreach_get("color", values)
    return values.reshape(-1, 4)[:, :3]


def positions(obj):
    co = np.empty(3 * len(obj.data.vertices))
    obj.data.vertices.foreach_get("co", co)
    return co.reshape(-1, 3)


def values_at(obj, points):
    """(N, 3) attribute values of a planar z-up mesh interpolated at the (N, 2)
    points (x, y), linearly over each polygon's fan of triangles: what a render
    shows there, however the mesh is cut. NaN where no polygon covers a point."""
    p, v = positions(obj), attribute(obj)
    out = np.full((len(points), 3), np.nan)
    for poly in obj.data.polygons:
        idx = list(poly.vertices)
        for k in range(1, len(idx) - 1):
            a, b, c = p[idx[0], :2], p[idx[k], :2], p[idx[k + 1], :2]
            m = np.array([b - a, c - a]).T
            if abs(np.linalg.det(m)) < 1e-14:
                continue
            uv = np.linalg.solve(m, (points - a).T).T
            w = np.column_stack([1 - uv.sum(axis=1), uv])
            hit = np.all(w >= -1e-9, axis=1) & np.isnan(out[:, 0])
            out[hit] = w[hit] @ v[[idx[0], idx[k], idx[k + 1]]]
    return out


def results(scene):
    return {o[result_state.RESULT_TAG]: o for o in result_state.result_objects(scene)}


def luminance(rgb):
    return rgb @ np.array([0.2126, 0.7152, 0.0722])


class BundledScenesTest(unittest.TestCase):
    def test_bundled_scenes_solve_without_warnings(self):
        # What a user opens first must not warn on every solve: full_office
        # named its chair's back on its seat as "faces in the same place"
        # (solids touching, not a doubled surface), the Cornell box its
        # published non-planar wall as repaired.
        for name in (*catalog.SCENES, *catalog.CONTACT_SCENES, *catalog.LIGHT_SCENES):
            with self.subTest(scene=name):
                scene = open_scene(name)
                scene.radiosity.quality = 0.0
                self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                self.assertTrue(scene.radiosity.stats.valid)
                self.assertEqual(scene.radiosity.stats.warning, "")


class SolveCubeTest(unittest.TestCase):
    def test_smallest_element_bounds_refinement(self):
        counts = {}
        for size in (0.0, 0.5):
            scene = open_scene("cube")
            scene.radiosity.oracle = 'PERCEPTUAL'
            scene.radiosity.quality = 0.8
            scene.radiosity.min_element_size = size
            self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
            counts[size] = scene.radiosity.stats.elements
        self.assertLess(counts[0.5], counts[0.0] / 2)

    def test_every_oracle(self):
        for oracle in oracles.IDENTIFIERS:
            with self.subTest(oracle=oracle):
                scene = open_scene("cube")
                scene.radiosity.oracle = oracle
                self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
                stats = scene.radiosity.stats
                self.assertTrue(stats.valid)
                self.assertEqual(stats.status, "Converged")
                self.assertGreater(stats.elements, 24)
                self.assertGreater(stats.links, 0)
                self.check_result(scene)

    def check_result(self, scene):
        out = results(scene)
        meshes = {o.name for o in scene.objects if o.type == 'MESH' and not o.get(result_state.RESULT_TAG)}
        self.assertEqual(set(out), meshes)
        coll = result_state.result_collection(scene, create=False)
        self.assertEqual(coll.name, "Radiosity")
        for name, obj in out.items():
            self.assertEqual(obj.users_collection[0], coll)
            attr = obj.data.color_attributes["Radiosity"]
            self.assertEqual((attr.data_type, attr.domain), ('FLOAT_COLOR', 'POINT'))
            self.assertEqual(obj.data.color_attributes.active_color.name, "Radiosity")
            names = [a.name for a in obj.data.color_attributes]
            self.assertEqual(names[obj.data.color_attributes.render_color_index], "Radiosity")
            values = attribute(obj)
            self.assertEqual(len(values), len(obj.data.vertices))
            self.assertTrue(np.all(np.isfinite(values)), name)
            self.assertEqual(obj.data.materials[0].name, bake.MATERIAL_NAME)
            # The original is hidden in renders and the viewport, not edited.
            original = scene.objects[name]
            self.assertTrue(original.hide_render)
            self.assertNotIn("Radiosity", original.data.color_attributes)
        # The light shows its own radiance (12, cube.py), on its lit side.
        np.testing.assert_allclose(attribute(out["Light"]), 12.0, rtol=1e-5)
        # Refinement happened where light changes: the floor has far more vertices than 4.
        self.assertGreater(len(out["Floor"].data.vertices), 50)

    def test_lit_brighter_than_shadowed_and_colour_bleeding(self):
        scene = open_scene("cube")
        bpy.ops.radiosity.solve()
        out = results(scene)
        floor = out["Floor"]
        # The small cube stands at (0.3, 0.05) turned 20 degrees; right next to
        # it, away from the light, the floor is in its shadow; under the light
        # (x, y near 0, cube's left side) and far in the open it is lit.
        # Compared where a render would: at points, interpolated, so that how
        # the floor is cut does not decide which points are looked at.
        cube = scene.objects["Cube"]
        centre = np.array(cube.location[:2])
        grid = np.stack(np.meshgrid(np.linspace(-1, 1, 81), np.linspace(-1, 1, 81)), axis=-1).reshape(-1, 2)
        d = np.linalg.norm(grid - centre, axis=1)
        away = (grid - centre) @ (centre / np.linalg.norm(centre))
        shadow = grid[(d > 0.36) & (d < 0.45) & (away > 0.3)]
        lit = grid[np.linalg.norm(grid - [-0.3, -0.3], axis=1) < 0.15]
        v_shadow, v_lit = luminance(values_at(floor, shadow)), luminance(values_at(floor, lit))
        self.assertTrue(len(shadow) > 5 and len(lit) > 5)
        self.assertFalse(np.isnan(v_shadow).any() or np.isnan(v_lit).any(), "the floor has holes")
        self.assertGreater(v_lit.mean(), 1.5 * v_shadow.mean())
        # The cube's top (facing the light) is brighter than its sides.
        cube_out = out["Cube"]
        cp, cv = positions(cube_out), luminance(attribute(cube_out))
        top = cp[:, 2] > 0.499
        self.assertGreater(cv[top].mean(), cv[~top].mean())
        # Colour bleeding: the white back wall is redder near the red left wall
        # (x = -1) than near the green right wall (x = +1).
        back = out["Wall.Back"]
        bp, bv = positions(back), attribute(back)
        redness = bv[:, 0] / np.maximum(bv[:, 1], 1e-9)
        near_red, near_green = bp[:, 0] < -0.8, bp[:, 0] > 0.8
        self.assertGreater(redness[near_red].mean(), 1.1 * redness[near_green].mean())
        self.assertGreater(redness[near_red].mean(), 1.05)   # white is red/green = 1

    def test_resolve_replaces_results(self):
        scene = open_scene("cube")
        bpy.ops.radiosity.solve()
        first = sorted(o.name for o in result_state.result_objects(scene))
        mesh_count = len(bpy.data.meshes)
        scene.radiosity.oracle = 'STANDARD'
        bpy.ops.radiosity.solve()
        second = sorted(o.name for o in result_state.result_objects(scene))
        self.assertEqual(first, second)
        self.assertEqual(len(bpy.data.meshes), mesh_count)
        self.assertEqual(len([c for c in bpy.data.collections if c.get(result_state.RESULT_TAG)]), 1)
        self.assertEqual(len([m for m in bpy.data.materials if m.get(result_state.MATERIAL_TAG)]), 1)
        # Hidden originals are still solved (not dropped because we hid them).
        self.assertEqual(len(second), 8)

    def test_clear_and_toggle_restore_the_originals(self):
        scene = open_scene("cube")
        before = scene_snapshot(scene)
        bpy.ops.radiosity.solve()
        self.assertEqual(bpy.ops.radiosity.toggle_result(), {'FINISHED'})
        self.assertFalse(scene.objects["Floor"].hide_render)
        self.assertTrue(all(o.hide_render for o in result_state.result_objects(scene)))
        bpy.ops.radiosity.toggle_result()
        self.assertTrue(scene.objects["Floor"].hide_render)
        self.assertFalse(any(o.hide_render for o in result_state.result_objects(scene)))
        bpy.ops.radiosity.clear()
        after = scene_snapshot(scene)
        # Everything as before but the shared emission material, kept for re-use.
        after["materials"].remove(bake.MATERIAL_NAME)
        self.assertEqual(after, before)

    def test_the_users_shading_comes_back(self):
        # A solve shows its result flat-lit with attribute colours; Toggle and
        # Remove put back how the user had shaded each 3D view.
        scene = open_scene("cube")
        views = [s for scr in bpy.data.screens for a in scr.areas for s in a.spaces if s.type == 'VIEW_3D']
        if not views:
            self.skipTest("no 3D views in this Blender's file")
        for space in views:
            space.shading.color_type, space.shading.light = 'MATERIAL', 'MATCAP'
            space.shading.show_backface_culling = False

        def shaded(result):
            expected = ({'ATTRIBUTE', 'VERTEX'}, {'FLAT'}, True) if result else ({'MATERIAL'}, {'MATCAP'}, False)
            return all(s.shading.color_type in expected[0] and s.shading.light in expected[1]
                       and s.shading.show_backface_culling == expected[2] for s in views)

        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        self.assertTrue(shaded(True))
        bpy.ops.radiosity.toggle_result()
        self.assertTrue(shaded(False))
        bpy.ops.radiosity.toggle_result()
        self.assertTrue(shaded(True))
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})  # a second solve saves nothing new
        bpy.ops.radiosity.clear()
        self.assertTrue(shaded(False))
        # Without "View Result" the views are left alone.
        scene.radiosity.view_result = False
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        self.assertTrue(shaded(False))

    def test_undo_restores(self):
        # Global (memfile) undo works in background mode, but operators called
        # from a script push no undo step of their own (the window manager does
        # that for UI calls of an operator with 'UNDO', as this one has), and
        # ed.undo's poll fails with fewer than two steps. So the test pushes
        # the steps the UI would: before, and after the solve; then undoes.
        scene = open_scene("cube")
        before = scene_snapshot(scene)
        bpy.ops.ed.undo_push(message="before solve")
        bpy.ops.radiosity.solve()
        bpy.ops.ed.undo_push(message="Solve Radiosity")
        self.assertTrue(result_state.result_objects(bpy.context.scene))
        bpy.ops.ed.undo()
        scene = bpy.context.scene
        self.assertFalse(result_state.result_objects(scene))
        self.assertEqual(scene_snapshot(scene), before)

    def test_original_output(self):
        scene = open_scene("cube")
        scene.radiosity.output = 'ORIGINAL'
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        self.assertFalse(result_state.result_objects(scene))
        floor = scene.objects["Floor"]
        self.assertFalse(floor.hide_render)
        attr = floor.data.color_attributes["Radiosity"]
        self.assertEqual((attr.data_type, attr.domain), ('FLOAT_COLOR', 'CORNER'))
        values = np.empty(4 * len(attr.data), dtype=np.float32)
        attr.data.foreach_get("color", values)
        self.assertTrue(np.all(np.isfinite(values)))
        # The corners of the cube's top: lit, so non-zero.
        top = scene.objects["Cube"].data.color_attributes["Radiosity"]
        self.assertEqual(len(top.data), 20)
        # BOTH writes both.
        scene.radiosity.output = 'BOTH'
        bpy.ops.radiosity.solve()
        self.assertTrue(result_state.result_objects(scene))
        self.assertIn("Radiosity", floor.data.color_attributes)

    def test_wireframe_option(self):
        scene = open_scene("cube")
        scene.radiosity.show_wireframe = True
        bpy.ops.radiosity.solve()
        self.assertTrue(all(o.show_wire for o in result_state.result_objects(scene)))
        scene.radiosity.show_wireframe = False
        self.assertFalse(any(o.show_wire for o in result_state.result_objects(scene)))


class RelightTest(unittest.TestCase):
    """A second solve after only the lighting changed starts from the first's
    elements and links (addon/solve/solve_reuse.py); any other change links anew and
    the statistics say why."""

    def setUp(self):
        self.scene = open_scene("cube")
        self.addCleanup(solve_reuse.forget)

    def light_strength(self):
        return bpy.data.materials["Light"].node_tree.nodes["Emission"].inputs["Strength"]

    def means(self):
        return {name: attribute(obj).mean(axis=0) for name, obj in results(self.scene).items()}

    def test_a_stronger_light_relights_to_what_a_solve_from_nothing_gives(self):
        bpy.ops.radiosity.solve()
        stats = self.scene.radiosity.stats
        self.assertFalse(stats.relit)
        self.assertEqual(stats.relinked_because, "")  # nothing was kept before
        self.assertGreater(solve_reuse.kept_bytes(self.scene), 0)
        # Every radiance doubles, so no refinement decision changes (they read
        # radiances relative to the adaptation level): the same meshes, twice as
        # bright, to the solve's tolerance.
        first = {name: attribute(obj) for name, obj in results(self.scene).items()}
        self.light_strength().default_value *= 2.0
        bpy.ops.radiosity.solve()
        self.assertTrue(stats.relit, stats.relinked_because)
        relit = {name: attribute(obj) for name, obj in results(self.scene).items()}
        self.assertEqual(first.keys(), relit.keys())
        bright = max(float(v.max()) for v in relit.values())
        for name in first:
            self.assertEqual(relit[name].shape, first[name].shape, name)
            np.testing.assert_allclose(relit[name], 2.0 * first[name], rtol=0, atol=1e-4 * bright, err_msg=name)

    def test_a_new_wall_colour_relights_close_to_a_solve_from_nothing(self):
        # Perceptual (relit within 0.1 % of fresh, standard too): Noticeable
        # refines after the light, so the red wall's mesh kept for the blue one
        # differs more, relit 2.4 % above fresh on the wall that changed.
        self.scene.radiosity.oracle = 'PERCEPTUAL'
        bpy.ops.radiosity.solve()
        bsdf = bpy.data.materials["Red"].node_tree.nodes["Principled BSDF"]
        bsdf.inputs["Base Color"].default_value = (0.2, 0.3, 0.8, 1.0)
        bpy.ops.radiosity.solve()
        self.assertTrue(self.scene.radiosity.stats.relit, self.scene.radiosity.stats.relinked_because)
        relit = self.means()
        solve_reuse.forget(self.scene)
        bpy.ops.radiosity.solve()
        self.assertFalse(self.scene.radiosity.stats.relit)
        fresh = self.means()
        for name in fresh:
            np.testing.assert_allclose(relit[name], fresh[name], rtol=0.02, atol=1e-4, err_msg=name)

    def test_a_moved_object_links_anew_and_says_why(self):
        bpy.ops.radiosity.solve()
        self.scene.objects["Cube"].location.x += 0.1
        bpy.ops.radiosity.solve()
        stats = self.scene.radiosity.stats
        self.assertFalse(stats.relit)
        self.assertEqual(stats.relinked_because, "the geometry changed")

    def test_remove_result_forgets_the_kept_solve(self):
        bpy.ops.radiosity.solve()
        self.assertGreater(solve_reuse.kept_bytes(self.scene), 0)
        bpy.ops.radiosity.clear()
        self.assertEqual(solve_reuse.kept_bytes(self.scene), 0)


class DoubledWallTest(unittest.TestCase):
    def test_a_doubled_wall_solves_like_one_and_is_named(self):
        # An imported model often carries a face twice (z-fighting in a
        # render): the solver counts the surface once, and the warning says so.
        def solve(doubled):
            scene = open_scene("cube")
            wall = next(o for o in scene.objects if o.type == 'MESH' and "Wall" in o.name)
            if doubled:
                copy = wall.copy()   # shares the mesh: every face of the copy coincides
                copy.name = "Duplicate of wall"
                scene.collection.objects.link(copy)
            self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
            values = np.concatenate([attribute(o) for o in result_state.result_objects(scene)])
            return scene.radiosity.stats.warning, luminance(values).mean(), wall.name

        single_warning, single, _ = solve(False)
        doubled_warning, doubled, name = solve(True)
        self.assertNotIn("same place", single_warning)
        self.assertIn("faces in the same place, counted once: Duplicate of wall and %s" % name, doubled_warning)
        self.assertLess(abs(doubled / single - 1), 0.01)


class RoughLookHintTest(unittest.TestCase):
    def test_a_solve_stopped_while_linking_says_its_result_is_the_rough_look(self):
        stats = {"stopped_by": "time_budget", "passes": 0, "ray_pass_rays": 32, "seconds_linking": 88.4}
        hint = pipeline.rough_look_hint("sampled", stats)
        self.assertIn("Rough look only: the Time Limit ran out while linking (88 s)", hint)
        self.assertIn("raise the Time Limit", hint)
        self.assertNotIn("Sampled", hint)
        self.assertIn("use Visibility 'Sampled'", pipeline.rough_look_hint("exact", stats))
        self.assertIn("the memory limit was reached",
                      pipeline.rough_look_hint("sampled", dict(stats, stopped_by="memory")))
        self.assertIn("it was cancelled", pipeline.rough_look_hint("sampled", dict(stats, stopped_by="cancel")))
        # A pass finished, or the solve converged: the result is solved.
        self.assertEqual(pipeline.rough_look_hint("sampled", dict(stats, passes=1)), "")
        self.assertEqual(pipeline.rough_look_hint("sampled", dict(stats, stopped_by="quality")), "")
        # Stopped before the ray pass finished: nothing was kept to describe.
        self.assertEqual(pipeline.rough_look_hint("sampled", dict(stats, ray_pass_rays=0)), "")


class VisibilityHintTest(unittest.TestCase):
    def test_slow_exact_linking_suggests_sampled_visibility(self):
        hint = pipeline.visibility_hint("exact", {"seconds_linking": 42.0})
        self.assertIn("Sampled", hint)
        self.assertIn("42 s", hint)
        self.assertIn("(418,452 links)", pipeline.visibility_hint("exact", {"seconds_linking": 12.0,
                                                                            "links": 418452}))
        self.assertEqual(pipeline.visibility_hint("exact", {"seconds_linking": 2.0}), "")
        self.assertEqual(pipeline.visibility_hint("sampled", {"seconds_linking": 42.0}), "")
        self.assertEqual(pipeline.visibility_hint("exact", {}), "")


class FailureTest(unittest.TestCase):
    def solve_error(self):
        with self.assertRaises(RuntimeError) as caught:
            bpy.ops.radiosity.solve()
        message = str(caught.exception)
        self.assertNotIn("Traceback", message)
        return message

    def test_no_emitter_changes_nothing(self):
        scene = open_scene("cube")
        for mat in bpy.data.materials:
            for node in mat.node_tree.nodes:
                if node.type == 'EMISSION':
                    node.inputs["Strength"].default_value = 0.0
        # A point light of strength 0 and no world light nothing.
        point = bpy.data.objects.new("Point", bpy.data.lights.new("Point", 'POINT'))
        point.data.energy = 0.0
        scene.collection.objects.link(point)
        scene.world = None
        before = scene_snapshot(scene)
        message = self.solve_error()
        self.assertIn("No light to solve", message)
        self.assertEqual(scene_snapshot(scene), before)

    def test_only_degenerate_faces(self):
        scene = open_scene("cube")
        for obj in list(scene.objects):
            if obj.type == 'MESH':
                bpy.data.objects.remove(obj)
        mesh = bpy.data.meshes.new("Flat")
        mesh.from_pydata([(0, 0, 0), (1, 0, 0), (2, 0, 0), (3, 0, 0)], [], [(0, 1, 2, 3)])
        mesh.materials.append(bpy.data.materials["Light"])
        scene.collection.objects.link(bpy.data.objects.new("Flat", mesh))
        before = scene_snapshot(scene)
        message = self.solve_error()
        self.assertIn("degenerate", message)
        self.assertEqual(scene_snapshot(scene), before)

    def test_empty_scene(self):
        scene = open_scene("cube")
        for obj in list(scene.objects):
            if obj.type == 'MESH':
                bpy.data.objects.remove(obj)
        before = scene_snapshot(scene)
        self.assertIn("Nothing to solve", self.solve_error())
        self.assertEqual(scene_snapshot(scene), before)


class Reports:
    """Stand-in for the operator: collects reports, runs the operator's methods."""
    _conclude = operators.RADIOSITY_OT_solve._conclude
    _unexpected = operators.RADIOSITY_OT_solve._unexpected

    def __init__(self):
        self.reports = []

    def report(self, kind, message):
        self.reports.append((kind, message))


class CancelTest(unittest.TestCase):
    """The interactive path without a window: worker thread, cancel token, conclude."""

    def run_worker(self, cancel_at_pass):
        scene = open_scene("cube")
        scene.radiosity.quality = 1.0
        self.before = scene_snapshot(scene)
        solver = native.load()
        op = Reports()
        job = pipeline.prepare(bpy.context, solver)
        token = solver.CancelToken()
        seen = []

        def progress(p):
            seen.append(dict(p))
            job.progress.update(p)
            if p.get("pass", 0) >= cancel_at_pass:
                token.cancel()

        if cancel_at_pass == 0:
            token.cancel()

        def work():
            try:
                job.result = solver.solve(job.native_scene, progress=progress, cancel=token, **job.options)
            except BaseException as err:
                job.error = err

        thread = threading.Thread(target=work)
        thread.start()
        thread.join(120)
        self.assertFalse(thread.is_alive())
        return scene, op, job, op._conclude(bpy.context, job), seen

    def test_cancel_keeps_last_complete_pass(self):
        scene, op, job, result, seen = self.run_worker(cancel_at_pass=2)
        self.assertEqual(result, {'FINISHED'}, op.reports)
        self.assertTrue(job.result.stats["cancelled"])
        self.assertEqual(scene.radiosity.stats.status, "Cancelled (last complete pass kept)")
        self.assertTrue(seen)
        for obj in result_state.result_objects(scene):
            values = attribute(obj)
            self.assertTrue(np.all(np.isfinite(values)))
        self.assertEqual(len(result_state.result_objects(scene)), 8)

    def test_cancel_before_first_pass_changes_nothing(self):
        scene, op, job, result, _ = self.run_worker(cancel_at_pass=0)
        self.assertEqual(result, {'CANCELLED'})
        self.assertIn("cancelled before the first pass", op.reports[-1][1])
        self.assertEqual(scene_snapshot(scene), self.before)


class CommandLineTest(unittest.TestCase):
    def test_background_python_expr(self):
        # The add-on enabled the way a user's Blender has it: found in a user
        # scripts folder (BLENDER_USER_SCRIPTS/addons/radiosity) and enabled
        # with --addons; then the documented one-liner.
        path = build_file("cube")
        with tempfile.TemporaryDirectory() as scripts:
            os.makedirs(os.path.join(scripts, "addons"))
            os.symlink(os.path.join(ADDON_DIR, "radiosity"), os.path.join(scripts, "addons", "radiosity"))
            out = os.path.join(scripts, "solved.blend")
            expr = ("import bpy; bpy.ops.radiosity.solve(); "
                    "bpy.ops.wm.save_as_mainfile(filepath=%r)" % out)
            env = dict(os.environ, BLENDER_USER_SCRIPTS=scripts)
            proc = subprocess.run([bpy.app.binary_path, "-b", "--factory-startup", "--addons", "radiosity",
                                   path, "--python-exit-code", "1", "--python-expr", expr],
                                  env=env, capture_output=True, text=True, timeout=300)
            self.assertEqual(proc.returncode, 0, proc.stdout[-2000:] + proc.stderr[-2000:])
            self.assertTrue(os.path.exists(out))
            bpy.ops.wm.open_mainfile(filepath=out)
        scene = bpy.context.scene
        self.assertEqual(len(result_state.result_objects(scene)), 8)
        self.assertTrue(scene.radiosity.stats.valid)


if __name__ == "__main__":
    unittest.main()
