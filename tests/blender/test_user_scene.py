"""What users' scenes hold that the add-on must live with (headless Blender):

- user objects, meshes, materials and collections named as the add-on names its
  results: solve, re-solve, toggle and remove leave every one of them as it was
  (Blender 3.4, asked to give an ID a taken name, renames the other one);
- a colour attribute of the user's own named as the add-on's: never
  overwritten or removed, and named in the warning;
- NaN and Inf vertex coordinates: those faces are left out and named, the rest
  solves, and no NaN reaches the result;
- broken faces (a bent quad, a bow-tie): repaired or left out, and named;
- Image Texture nodes without pixels (no image, a missing or unreadable file):
  magenta, as Cycles renders them, named in the warning;
- what Cycles does not render (disabled in renders, itself or by a collection,
  or in an excluded collection) takes no part in the solve; what the viewport
  only hides does (the export is checked against Cycles renders).
"""

import math
import os
import re
import tempfile
import unittest

import bpy
import numpy as np

from radiosity.read import export
from radiosity.write import bake, result_state
from test_solve import open_scene
from scene_kit import emission_material  # noqa: E402  (scenes/ is on the path: test_solve)

TMP = tempfile.mkdtemp(prefix="radiosity-user-scene-")


def solve(expect='FINISHED'):
    result = bpy.ops.radiosity.solve()
    assert result == {expect}, result
    return bpy.context.scene.radiosity.stats.warning


def quad(scene, name, z, size=1.0, facing_down=False, collection=None):
    s = size / 2
    verts = [(-s, -s, z), (s, -s, z), (s, s, z), (-s, s, z)]
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts, [], [(0, 3, 2, 1) if facing_down else (0, 1, 2, 3)])
    obj = bpy.data.objects.new(name, mesh)
    (collection or scene.collection).objects.link(obj)
    return obj


def all_finite_results(scene):
    """Every number the result put in the scene is finite: positions, attributes, UV maps."""
    for obj in result_state.result_objects(scene):
        mesh = obj.data
        co = np.empty(3 * len(mesh.vertices))
        mesh.vertices.foreach_get("co", co)
        yield obj.name, "positions", co
        for attr in mesh.color_attributes:
            v = np.empty(4 * len(attr.data), dtype=np.float32)
            attr.data.foreach_get("color", v)
            yield obj.name, attr.name, v
        for layer in mesh.uv_layers:
            uv = np.empty(2 * len(layer.data), dtype=np.float32)
            layer.data.foreach_get("uv", uv)
            yield obj.name, layer.name, uv
    for obj in scene.objects:
        attr = obj.data.color_attributes.get(bake.ATTRIBUTE) if obj.type == 'MESH' and \
            not obj.get(result_state.RESULT_TAG) else None
        if attr is not None:
            v = np.empty(4 * len(attr.data), dtype=np.float32)
            attr.data.foreach_get("color", v)
            yield obj.name, "original " + attr.name, v


class UserNamesTest(unittest.TestCase):
    """The user's IDs named as results keep their names and data; the results take others."""

    def user_state(self):
        """name -> what the user would see of each of their clashing IDs."""
        layer = bpy.context.view_layer
        state = {}
        for obj in self.objects:
            state["object " + obj.name] = (obj.type, obj.data.name if obj.data else None,
                                           tuple(obj.location), obj.hide_render, obj.hide_viewport,
                                           obj.hide_get(view_layer=layer), obj.get("mine"))
        for mesh in self.meshes:
            state["mesh " + mesh.name] = (len(mesh.vertices), mesh.users, mesh.get("mine"),
                                          sorted(a.name for a in mesh.attributes))
        for mat in self.materials:
            state["material " + mat.name] = (mat.users, mat.get("mine"))
        state["collection " + self.collection.name] = (self.collection.get("mine"),
                                                       sorted(o.name for o in self.collection.objects))
        return state

    def test_results_never_take_a_user_name(self):
        scene = open_scene("cube")
        # Empties named as result objects would be (and as retired ones), a solved
        # mesh object named so, user meshes and materials named as the add-on's.
        names = ["Cube Radiosity", "Floor Radiosity.001", "Wall.Left Radiosity (previous radiosity result)",
                 "Light Radiosity"]
        self.objects = []
        for name in names:
            obj = bpy.data.objects.new(name, None)
            scene.collection.objects.link(obj)
            self.objects.append(obj)
        solved = quad(scene, "Ceiling Radiosity", -0.5, facing_down=True)   # under the floor, unlit
        self.objects.append(solved)
        self.meshes = [solved.data]
        for name in ("Cube Radiosity", "Floor Radiosity", "Wall.Back Radiosity (previous radiosity result)"):
            mesh = bpy.data.meshes.new(name)
            mesh.from_pydata([(0, 0, 0), (1, 0, 0), (0, 1, 0)], [], [(0, 1, 2)])
            mesh.use_fake_user = True
            self.meshes.append(mesh)
        self.materials = []
        for name in (bake.MATERIAL_NAME, "White Radiosity Light", "Radiosity Light Default"):
            mat = bpy.data.materials.new(name)
            mat.use_fake_user = True
            self.materials.append(mat)
        self.collection = bpy.data.collections.new(result_state.COLLECTION_NAME)
        scene.collection.children.link(self.collection)
        empty = bpy.data.objects.new("In user collection", None)
        self.collection.objects.link(empty)
        self.objects.append(empty)
        for block in self.objects + self.meshes + self.materials + [self.collection]:
            block["mine"] = block.name
        before = self.user_state()
        user_names = {o.name for o in self.objects}

        def check(step, attributes=True):
            state = self.user_state()
            if not attributes:   # the original-mesh output's attribute stays until removed
                key = "mesh " + solved.data.name
                state[key] = state[key][:3] + (sorted(set(state[key][3]) - {bake.ATTRIBUTE}),)
            self.assertEqual(state, before, step)
            results = result_state.result_objects(scene)
            self.assertTrue(all(o.get(result_state.RESULT_TAG) for o in results), step)
            self.assertFalse({o.name for o in results} & user_names, step)
            self.assertFalse(any(o.get("mine") for o in results), step)

        def check_hidden_while_shown(step):
            state = self.user_state()
            # Only the solved user object is hidden (as an original), nothing else changes.
            key = "object " + solved.name
            self.assertTrue(state[key][3] and state[key][5], step)
            state[key] = before[key]
            # ... and it may carry the attribute of the original-mesh output.
            key = "mesh " + solved.data.name
            state[key] = state[key][:3] + (sorted(set(state[key][3]) - {bake.ATTRIBUTE}),)
            self.assertEqual(state, before, step)

        for output in ('BOTH', 'LIGHTING', 'REFINED'):
            scene.radiosity.output = output
            solve()
            check_hidden_while_shown("solve " + output)
            names = sorted(o.name for o in result_state.result_objects(scene))
            self.assertIn("Cube Radiosity.001", names)    # the user's holds "Cube Radiosity"
            self.assertIn("Ceiling Radiosity Radiosity", names)
        self.assertEqual(bpy.ops.radiosity.toggle_result(), {'FINISHED'})
        check("toggle to originals", attributes=False)
        self.assertEqual(bpy.ops.radiosity.toggle_result(), {'FINISHED'})
        check_hidden_while_shown("toggle to result")
        scene.radiosity.output = 'ORIGINAL'
        solve()
        self.assertEqual(bpy.ops.radiosity.clear(), {'FINISHED'})
        check("remove")
        self.assertFalse(result_state.result_objects(scene))
        self.assertFalse([o for o in bpy.data.objects if o.get(result_state.RESULT_TAG)])


class UserAttributeTest(unittest.TestCase):
    def test_a_users_own_radiosity_attribute_is_never_touched(self):
        scene = open_scene("cube")
        cube = scene.objects["Cube"]
        mine = cube.data.color_attributes.new(bake.ATTRIBUTE, 'BYTE_COLOR', 'POINT')
        values = np.linspace(0.0, 1.0, 4 * len(mine.data), dtype=np.float32)
        mine.data.foreach_set("color", values)
        stored = np.empty_like(values)
        mine.data.foreach_get("color", stored)  # as bytes keep them

        def unchanged():
            attr = cube.data.color_attributes.get(bake.ATTRIBUTE)
            self.assertIsNotNone(attr)
            self.assertEqual((attr.data_type, attr.domain), ('BYTE_COLOR', 'POINT'))
            now = np.empty_like(values)
            attr.data.foreach_get("color", now)
            np.testing.assert_array_equal(now, stored)

        for output in ('ORIGINAL', 'BOTH'):
            scene.radiosity.output = output
            warning = solve()
            self.assertIn('no attribute on Cube (it has its own "%s" attribute)' % bake.ATTRIBUTE, warning)
            unchanged()
            # The other originals get theirs.
            others = [o for o in scene.objects
                      if o.type == 'MESH' and o is not cube and not o.get(result_state.RESULT_TAG)]
            self.assertTrue(any(o.data.color_attributes.get(bake.ATTRIBUTE) for o in others))
        self.assertEqual(bpy.ops.radiosity.clear(), {'FINISHED'})
        unchanged()
        self.assertFalse(any(o.data.color_attributes.get(bake.ATTRIBUTE) for o in others),
                         "Remove takes the attributes the add-on wrote")


class NonFiniteCoordinatesTest(unittest.TestCase):
    def test_faces_with_nan_or_inf_are_left_out_and_named(self):
        scene = open_scene("cube")
        cube = scene.objects["Cube"]
        cube.data.vertices[0].co = (math.nan, 0.0, 0.0)
        # Blender stores an Inf set this way as the largest float: Inf all the same.
        cube.data.vertices[1].co = (0.0, math.inf, 0.0)
        faces_of_vertex = sum(1 for p in cube.data.polygons if {0, 1} & set(p.vertices))
        # A second object wholly at infinity, set through foreach_set.
        lost = quad(scene, "Lost", 1.0)
        lost.data.vertices.foreach_set("co", np.full(12, np.inf, dtype=np.float32))
        for output in ('BOTH', 'LIGHTING'):
            scene.radiosity.output = output
            warning = solve()
            self.assertIn("non-finite (NaN or Inf) coordinates, left out: Cube (%d of %d faces), Lost (all 1 face)"
                          % (faces_of_vertex, len(cube.data.polygons)), warning)
            names = {o.name for o in result_state.result_objects(scene)}
            self.assertIn("Cube Radiosity", names)
            self.assertNotIn("Lost Radiosity", names)
            for name, what, values in all_finite_results(scene):
                self.assertTrue(np.isfinite(values).all(), (output, name, what))
            # The cube's other faces are solved and lit; the attribute on the original
            # covers the faces solved (the rest stay black).
            cube_result = [o for o in result_state.result_objects(scene) if o.name == "Cube Radiosity"][0]
            self.assertEqual(len(cube_result.data.uv_layers), len(cube.data.uv_layers))
            if output == 'BOTH':
                attr = cube.data.color_attributes[bake.ATTRIBUTE]
                v = np.empty(4 * len(attr.data), dtype=np.float32)
                attr.data.foreach_get("color", v)
                self.assertGreater(v.reshape(-1, 4)[:, :3].max(), 0.05)

    def test_a_light_at_infinity_is_left_out(self):
        scene = open_scene("cube")
        light = bpy.data.objects.new("Far Light", bpy.data.lights.new("Far Light", 'POINT'))
        scene.collection.objects.link(light)
        light.location = (math.inf, 0.0, 1.0)
        warning = solve()
        self.assertIn("Far Light (a light)", warning)
        for name, what, values in all_finite_results(scene):
            self.assertTrue(np.isfinite(values).all(), (name, what))


class BrokenFacesTest(unittest.TestCase):
    def test_bent_quads_and_bow_ties_are_named(self):
        # An imported model's everyday faults: a quad with a lifted corner
        # (solved as Blender's two triangles) and a bow-tie (no inside: left out).
        scene = open_scene("cube")
        bent = quad(scene, "Bent", 0.5, size=0.4)
        bent.data.vertices[2].co.z += 0.1
        bow = quad(scene, "Bow", 0.6, size=0.4)
        bow.data.vertices[1].co, bow.data.vertices[2].co = bow.data.vertices[2].co.copy(), bow.data.vertices[1].co.copy()
        warning = solve()
        found = re.search(r"faces repaired: Bent: 1 face not planar: split into 2 planar triangles \(([0-9.]+) %\)",
                          warning)
        self.assertIsNotNone(found, warning)
        # The bend: the corners' largest distance from their best-fit plane over the diameter.
        q = np.array([v.co for v in bent.data.vertices])
        normal = np.cross(q[2] - q[0], q[3] - q[1])
        normal /= np.linalg.norm(normal)
        expected = 100 * np.max(np.abs((q - q.mean(axis=0)) @ normal)) / np.linalg.norm(q[2] - q[0])
        self.assertAlmostEqual(float(found.group(1)), expected, delta=0.01)
        self.assertIn("faces left out: Bow: 1 face its outline crosses itself", warning)
        names = {o.name for o in result_state.result_objects(scene)}
        self.assertIn("Bent Radiosity", names)
        self.assertNotIn("Bow Radiosity", names)
        for name, what, values in all_finite_results(scene):
            self.assertTrue(np.isfinite(values).all(), (name, what))


class MissingImageTest(unittest.TestCase):
    def textured(self, image):
        mat = bpy.data.materials.new("Textured")
        mat.use_nodes = True
        tree = mat.node_tree
        bsdf = next(n for n in tree.nodes if n.type == 'BSDF_PRINCIPLED')
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.image = image
        tree.links.new(tex.outputs["Color"], bsdf.inputs["Base Color"])
        return mat

    def test_images_without_pixels_are_magenta_and_named(self):
        garbage = os.path.join(TMP, "not an image.png")
        with open(garbage, "w") as f:
            f.write("not a PNG")
        for name in ("Missing", "not an image.png", None):
            with self.subTest(image=name):
                scene = open_scene("cube")
                image = None
                if name == "Missing":
                    image = bpy.data.images.new("Missing", 4, 4)
                    image.source = 'FILE'
                    image.filepath = os.path.join(TMP, "gone.png")
                elif name is not None:
                    image = bpy.data.images.load(garbage)
                scene.objects["Cube"].data.materials[0] = self.textured(image)
                bpy.context.view_layer.update()
                exported = export.export_scene(bpy.context)
                part = [i for i, p in enumerate(exported.parts) if p.name == "Cube"][0]
                rho = exported.arrays["reflectance"][exported.arrays["face_part"] == part]
                np.testing.assert_allclose(rho, np.tile(export.MISSING_IMAGE, (len(rho), 1)))
                self.assertEqual(exported.unmodelled, [])
                warning = solve()
                self.assertIn("read as magenta, as Cycles renders them", warning)
                self.assertIn(image.name if image is not None else "Image Texture without image", warning)
                if name == "Missing":
                    self.assertIn("gone.png", warning)
                for obj, what, values in all_finite_results(scene):
                    self.assertTrue(np.isfinite(values).all(), (obj, what))


# How a blocker between a light and the floor is kept out of the viewport or the render.
def _exclude(blocker, coll, layer):
    layer.layer_collection.children[coll.name].exclude = True


def _collection_eye(blocker, coll, layer):
    layer.layer_collection.children[coll.name].hide_viewport = True


HIDDEN = {   # name -> (how, does Cycles render it)
    "render-disabled object": (lambda b, c, l: setattr(b, "hide_render", True), False),
    "render-disabled collection": (lambda b, c, l: setattr(c, "hide_render", True), False),
    "excluded collection": (_exclude, False),
    "viewport-disabled object": (lambda b, c, l: setattr(b, "hide_viewport", True), True),
    "eye-hidden object": (lambda b, c, l: b.hide_set(True, view_layer=l), True),
    "viewport-disabled collection": (lambda b, c, l: setattr(c, "hide_viewport", True), True),
    "eye-hidden collection": (_collection_eye, True),
}


def blocker_scene(case):
    """A floor, a light above it facing down and, in a collection of its own, a
    blocker between them hidden as `case` says (None: no blocker)."""
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    layer = bpy.context.view_layer
    if scene.world is not None:
        scene.world.color = (0, 0, 0)
    quad(scene, "Floor", 0.0, size=4.0)
    light = quad(scene, "Lamp", 2.0, size=0.5, facing_down=True)
    light.data.materials.append(emission_material("Lamp", 20.0))
    if case is not None:
        coll = bpy.data.collections.new("Blockers")
        scene.collection.children.link(coll)
        blocker = quad(scene, "Blocker", 1.0, size=1.0, collection=coll)
        if case != "shown":
            HIDDEN[case][0](blocker, coll, layer)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.location = (0.0, 0.0, 0.5)
    camera.data.angle = math.radians(60)
    scene.camera = camera
    layer.update()
    return scene


def visibility_flags(scene):
    layer = bpy.context.view_layer
    flags = {o.name: (o.hide_render, o.hide_viewport, o.hide_get(view_layer=layer)) for o in scene.objects}
    for lc in layer.layer_collection.children:
        flags[lc.name] = (lc.exclude, lc.hide_viewport, lc.collection.hide_viewport, lc.collection.hide_render)
    return flags


def floor_centre():
    """The mean value of the refined floor's upper side within 0.2 m of the centre (under the blocker)."""
    mesh = bpy.data.objects["Floor Radiosity"].data
    attr = mesh.color_attributes[bake.ATTRIBUTE]
    values = np.empty(4 * len(attr.data), dtype=np.float32)
    attr.data.foreach_get("color", values)
    values = values.reshape(-1, 4)[:, :3].mean(axis=1)
    picked = {i for p in mesh.polygons if p.normal.z > 0 for i in p.vertices}
    near = [i for i in picked if abs(mesh.vertices[i].co.x) <= 0.2 and abs(mesh.vertices[i].co.y) <= 0.2]
    assert near
    return float(values[near].mean())


def cycles_floor(scene):
    """Mean of a small Cycles render of the floor under the blocker, from below the blocker."""
    scene.render.engine = 'CYCLES'
    scene.cycles.samples = 8
    scene.cycles.use_denoising = False
    scene.render.resolution_x = scene.render.resolution_y = 8
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.render.image_settings.file_format = 'OPEN_EXR'
    scene.render.filepath = os.path.join(TMP, "floor.exr")
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(scene.render.filepath, check_existing=False)
    pixels = np.array(image.pixels[:]).reshape(-1, 4)[:, :3]
    bpy.data.images.remove(image)
    return float(pixels.mean())


class RenderVisibilityTest(unittest.TestCase):
    """A blocker Cycles does not render changes nothing; one the viewport only hides shadows."""

    def test_solve_takes_what_cycles_renders(self):
        blocker_scene(None)
        solve()
        unblocked = floor_centre()
        blocker_scene("shown")
        solve()
        shadowed = floor_centre()
        self.assertLess(shadowed, 0.5 * unblocked)
        for case, (_, rendered) in HIDDEN.items():
            with self.subTest(case=case):
                scene = blocker_scene(case)
                flags = visibility_flags(scene)
                solve()
                value = floor_centre()
                if rendered:
                    self.assertAlmostEqual(value, shadowed, delta=0.02 * unblocked)
                else:
                    self.assertAlmostEqual(value, unblocked, delta=1e-6 * unblocked)
                # The flags are as the user set them (the floor and lamp now hidden as originals).
                bpy.ops.radiosity.clear()
                self.assertEqual(visibility_flags(scene), flags)

    def test_cycles_agrees(self):
        """Whether Cycles renders each hidden blocker (its shadow on the floor, seen
        from below the blocker) is what the export takes, in every Blender."""
        unblocked = cycles_floor(blocker_scene(None))
        shadowed = cycles_floor(blocker_scene("shown"))
        self.assertLess(shadowed, 0.8 * unblocked)
        for case, (_, rendered) in HIDDEN.items():
            with self.subTest(case=case):
                scene = blocker_scene(case)
                value = cycles_floor(scene)
                self.assertAlmostEqual(value, shadowed if rendered else unblocked,
                                       delta=0.1 * abs(unblocked - shadowed))
                with export.rendered_shown(bpy.context.view_layer):
                    parts = [p.name for p in export.export_scene(bpy.context).parts]
                self.assertEqual("Blocker" in parts, rendered)


if __name__ == "__main__":
    unittest.main()
