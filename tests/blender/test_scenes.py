"""The bundled scene builders make what the solver and the demo expect (headless Blender).

Each scene is built into a new scene of this Blender session, then checked:
quads only, a closed room with inward walls, one emitter facing down, a
camera inside looking at the occluder, Cycles settings, and a small render
that is neither black nor blown out.
"""

import os
import re
import sys
import tempfile
import unittest

import bpy
import numpy as np
from bpy_extras.object_utils import world_to_camera_view
from mathutils import Vector

SCENES_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scenes")
sys.path.insert(0, os.path.abspath(SCENES_DIR))

import build_scene  # noqa: E402
import catalog  # noqa: E402
import scene_kit as kit  # noqa: E402

# The object each scene's camera must see, and that casts the shadow.
SUBJECT = {"cube": "Cube", "office": "Table.Top", "full_office": "Table.Top",
           "dining_room": "Table.Top", "gradient_large_45": "Occluder", "gradient_small_45": "Occluder",
           "gradient_large_aligned": "Occluder", "gradient_small_aligned": "Occluder", "cornell_box": "Block.Short"}


def objects(scene):
    """The scene's objects by the name their builder gave them. Blender appends
    .001, .002 to names already taken in this session (the factory Cube, or the
    walls of a scene built earlier)."""
    return {re.sub(r"\.\d{3}$", "", o.name): o for o in scene.objects}


def world_polygons(obj):
    """(centres, normals, areas) of an object's polygons in world space."""
    mesh = obj.data
    n = len(mesh.polygons)
    centres, normals, areas = np.empty(3 * n), np.empty(3 * n), np.empty(n)
    mesh.polygons.foreach_get("center", centres)
    mesh.polygons.foreach_get("normal", normals)
    mesh.polygons.foreach_get("area", areas)
    m = np.array(obj.matrix_world)
    centres = centres.reshape(-1, 3) @ m[:3, :3].T + m[:3, 3]
    normals = normals.reshape(-1, 3) @ np.linalg.inv(m[:3, :3])  # inverse transpose
    normals /= np.linalg.norm(normals, axis=1, keepdims=True)
    return centres, normals, areas


def emission_strength(material):
    nodes = material.node_tree.nodes if material.use_nodes else []
    return sum(node.inputs["Strength"].default_value for node in nodes if node.type == 'EMISSION')


def render_pixels(scene):
    """F12 of `scene` with its own settings, written as OpenEXR (linear values):
    its pixels as (N, 4) RGBA."""
    scene.render.image_settings.file_format = 'OPEN_EXR'
    with tempfile.TemporaryDirectory() as tmp:
        scene.render.filepath = os.path.join(tmp, scene.name + ".exr")
        with bpy.context.temp_override(scene=scene):
            bpy.ops.render.render(write_still=True, scene=scene.name)
        image = bpy.data.images.load(scene.render.filepath)
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
    return pixels.reshape(-1, 4)


class SceneBuildersTest(unittest.TestCase):
    built = {}

    @classmethod
    def scene(cls, name):
        """Build `name` once into its own Blender scene."""
        if name not in cls.built:
            scene = bpy.data.scenes.new(name)
            build_scene.build(name, scene)
            scene.view_layers[0].update()  # evaluate matrix_world of the new objects
            cls.built[name] = scene
        return cls.built[name]

    def for_each_scene(self, check, only=None):
        for name in only or catalog.SCENES:
            with self.subTest(scene=name):
                check(name, self.scene(name))

    def test_catalog_has_a_module_per_scene(self):
        self.assertIn("cube", catalog.SCENES)
        self.assertIn("office", catalog.SCENES)
        with self.assertRaises(ValueError):
            build_scene.build("no_such_scene", bpy.context.scene)

    def test_render_of_a_bundled_scene_is_not_empty(self):
        # F12 as a user presses it, with the scene's own settings (fewer
        # samples): Debian's 3.4 has no denoiser, and with Denoise on (Cycles'
        # default) it rendered nothing. A scene of its own: the other render
        # test turns denoising off.
        scene = bpy.data.scenes.new("office_f12")
        build_scene.build("office", scene)
        self.assertEqual(scene.cycles.use_denoising, kit.cycles_denoiser_available())
        scene.cycles.samples, scene.render.resolution_percentage = 4, 10
        pixels = render_pixels(scene)
        bpy.data.scenes.remove(scene)
        self.assertGreater(float(np.median(pixels[:, :3])), 0.02)

    def test_quads_only(self):
        # But for the Cornell box's left wall: its published quad is not planar,
        # so it is the two triangles Blender renders it as.
        def check(name, scene):
            for obj in scene.objects:
                if obj.type != 'MESH':
                    continue
                sizes = np.empty(len(obj.data.polygons), dtype=np.int32)
                obj.data.polygons.foreach_get("loop_total", sizes)
                published_triangles = name == "cornell_box" and obj.name.startswith("Wall.Left")
                self.assertTrue(np.all(sizes == (3 if published_triangles else 4)), obj.name)
        self.for_each_scene(check)

    def test_room_is_closed_with_inward_walls(self):
        def check(name, scene):
            walls = [objects(scene)[n] for n in
                     ("Floor", "Ceiling", "Wall.Left", "Wall.Right", "Wall.Front", "Wall.Back")]
            corners = np.array([v.co for w in walls for v in w.data.vertices])
            lo, hi = corners.min(0), corners.max(0)
            size = hi - lo
            # A recessed light fills its opening in the ceiling.
            total = sum(world_polygons(w)[2].sum() for w in walls)
            light = world_polygons(objects(scene)["Light"])
            if abs(light[0][:, 2].max() - hi[2]) < 1e-9:
                total += light[2].sum()
            self.assertAlmostEqual(total, 2 * (size[0] * size[1] + size[1] * size[2] + size[0] * size[2]), 6)
            middle = (lo + hi) / 2
            for wall in walls:
                centres, normals, _ = world_polygons(wall)
                self.assertTrue(np.all(np.einsum("ij,ij->i", normals, middle - centres) > 0), wall.name)
        self.for_each_scene(check, only=catalog.ROOMS)

    def test_one_emitter_facing_down(self):
        def check(name, scene):
            emitters = [o for o in scene.objects if o.type == 'MESH'
                        and any(emission_strength(m) > 0 for m in o.data.materials)]
            self.assertEqual(emitters, [objects(scene)["Light"]])
            centres, normals, _ = world_polygons(emitters[0])
            np.testing.assert_allclose(normals, [[0, 0, -1]] * len(normals), atol=1e-6)
            self.assertFalse([o.name for o in scene.objects if o.type == 'LIGHT'])
        self.for_each_scene(check)

    def test_surfaces_are_diffuse_with_valid_reflectance(self):
        def check(name, scene):
            for obj in scene.objects:
                for mat in (obj.data.materials if obj.type == 'MESH' else []):
                    if emission_strength(mat) > 0:
                        continue
                    nodes = mat.node_tree.nodes
                    if "Principled BSDF" in nodes:
                        bsdf = nodes["Principled BSDF"]
                        rho = bsdf.inputs["Base Color"].default_value[:3]
                        self.assertEqual(kit.principled_input(bsdf, "Specular").default_value, 0.0, mat.name)
                    else:   # Lambertian: a Diffuse BSDF (scene_kit.lambertian_material)
                        rho = next(n for n in nodes if n.type == 'BSDF_DIFFUSE').inputs["Color"].default_value[:3]
                    self.assertTrue(all(0 <= c < 1 for c in rho), mat.name)
        self.for_each_scene(check)
        cube = self.scene("cube")
        left = objects(cube)["Wall.Left"].data.materials[0].diffuse_color
        right = objects(cube)["Wall.Right"].data.materials[0].diffuse_color
        self.assertGreater(left[0], 3 * left[1])    # red
        self.assertGreater(right[1], 2 * right[0])  # green

    def test_camera_inside_looking_at_the_subject(self):
        def check(name, scene):
            cam = scene.camera
            self.assertIsNotNone(cam)
            if name in catalog.ROOMS:
                walls = [v.co for n in ("Floor", "Ceiling") for v in objects(scene)[n].data.vertices]
                lo = np.min(np.array(walls), 0)
                hi = np.max(np.array(walls), 0)
                self.assertTrue(np.all(lo < np.array(cam.location)) and np.all(np.array(cam.location) < hi))
            subject = objects(scene)[SUBJECT[name]]
            x, y, depth = world_to_camera_view(scene, cam, subject.matrix_world.translation)
            self.assertTrue(0.1 < x < 0.9 and 0.1 < y < 0.9 and depth > 0, (x, y, depth))
        self.for_each_scene(check)

    def test_render_settings(self):
        def check(name, scene):
            self.assertEqual(scene.render.engine, 'CYCLES')
            self.assertEqual(scene.cycles.device, 'CPU')
            self.assertEqual(scene.view_settings.view_transform, 'Standard')
            self.assertEqual(scene.view_settings.look, 'None')
            self.assertEqual(scene.view_settings.exposure, 0.0)
        self.for_each_scene(check)

    def test_render_is_well_exposed(self):
        # A tiny, noisy render is enough to tell black or blown out from well lit.
        def check(name, scene):
            scene.render.resolution_percentage = 12
            scene.cycles.samples = 8
            scene.cycles.use_denoising = False
            luminance = render_pixels(scene)[:, :3] @ np.array([0.2126, 0.7152, 0.0722])
            if name in catalog.ROOMS:
                self.assertTrue(0.05 < np.median(luminance) < 0.6, np.median(luminance))
            else:  # an open set-up against a black world: judge the lit part
                lit = luminance[luminance > 0.01]
                self.assertGreater(len(lit), 0.2 * len(luminance))
                self.assertTrue(0.05 < np.median(lit) < 0.8, np.median(lit))
            self.assertLess(np.mean(luminance > 1.0), 0.05)
        self.for_each_scene(check)


class ContactScenesTest(unittest.TestCase):
    """The scenes of issue 12 have the contact they are named for, and the Cornell
    box is as published (millimetres in its own frame, y up: to_blender)."""

    def build(self, name, **params):
        scene = bpy.data.scenes.new(name)
        build_scene.build(name, scene, **params)
        scene.view_layers[0].update()
        return scene, objects(scene)

    def test_cornell_box_as_published_with_its_light_gap(self):
        import cornell_box as cb
        for gap in (1e-4, 1e-2):
            scene, objs = self.build("cornell_box", gap=gap)
            light = world_polygons(objs["Light"])
            ceiling = world_polygons(objs["Ceiling"])
            self.assertAlmostEqual(ceiling[0][0, 2] - light[0][0, 2], gap, places=6)   # float32 vertices
            self.assertAlmostEqual(light[2][0], 0.130 * 0.105, places=7)   # 130 x 105 mm
            np.testing.assert_allclose(light[1], [[0, 0, -1]], atol=1e-9)
        # Walls face into the box, blocks out of themselves; each block stands on the floor.
        inside = cb.to_blender((278.0, 274.4, 279.6))
        for name in ("Floor", "Ceiling", "Wall.Back", "Wall.Left", "Wall.Right"):
            centres, normals, _ = world_polygons(objs[name])
            self.assertGreater(float(np.dot(normals[0], inside - centres[0])), 0, name)
        for name, height in (("Block.Short", 0.165), ("Block.Tall", 0.330)):
            obj = objs[name]
            centres, normals, _ = world_polygons(obj)
            self.assertEqual(len(centres), 5, name)   # no bottom face
            middle = centres.mean(axis=0)
            self.assertTrue(np.all(np.einsum("ij,ij->i", normals, centres - middle) > 0), name)
            z = np.array([(obj.matrix_world @ v.co).z for v in obj.data.vertices])
            self.assertAlmostEqual(z.min(), 0.0, places=9)
            self.assertAlmostEqual(z.max(), height, places=6)
        # The published left wall is not planar: its fourth corner is off the other
        # three's plane. It is made of the two triangles Blender renders it as.
        wall = objs["Wall.Left"]
        self.assertEqual([len(f.vertices) for f in wall.data.polygons], [3, 3])
        p = np.array([wall.matrix_world @ v.co for v in wall.data.vertices])
        n = np.cross(p[1] - p[0], p[2] - p[0])
        self.assertGreater(abs(np.dot(n / np.linalg.norm(n), p[3] - p[0])), 1e-4)
        # The published camera; red on its left, green on its right (not mirrored).
        cam = scene.camera
        np.testing.assert_allclose(cam.location, (-0.278, -0.8, 0.273), atol=1e-9)
        self.assertEqual((cam.data.lens, cam.data.sensor_width), (35.0, 25.0))
        left = world_to_camera_view(scene, cam, Vector(world_polygons(objs["Wall.Left"])[0][0]))
        right = world_to_camera_view(scene, cam, Vector(world_polygons(objs["Wall.Right"])[0][0]))
        self.assertLess(left.x, 0.3)
        self.assertGreater(right.x, 0.7)
        self.assertGreater(objs["Wall.Left"].data.materials[0].diffuse_color[0], 5 * cb.RED[1])

    def test_box_bottom_face_lies_on_the_floor(self):
        scene, objs = self.build("box_on_floor")
        centres, normals, areas = world_polygons(objs["Box"])
        bottom = np.argmin(centres[:, 2])
        self.assertEqual(len(centres), 6)
        self.assertAlmostEqual(centres[bottom, 2], 0.0, places=9)
        np.testing.assert_allclose(normals[bottom], [0, 0, -1], atol=1e-9)
        self.assertEqual([o.data.type for o in scene.objects if o.type == 'LIGHT'], ['AREA'])

    def test_lamp_lies_on_the_table_top(self):
        import lamp_on_table
        scene, objs = self.build("lamp_on_table")
        lamp = world_polygons(objs["Lamp"])
        table = world_polygons(objs["Table"])
        top = np.argmax(table[0][:, 2])
        self.assertAlmostEqual(lamp[0][0, 2] - table[0][top, 2], lamp_on_table.LIFT, places=6)
        np.testing.assert_allclose(lamp[1], [[0, 0, 1]], atol=1e-9)
        corners = np.array([objs["Lamp"].matrix_world @ v.co for v in objs["Lamp"].data.vertices])
        t = np.array([objs["Table"].matrix_world @ v.co for v in objs["Table"].data.vertices])
        self.assertTrue(np.all(corners[:, :2] > t[:, :2].min(0)) and np.all(corners[:, :2] < t[:, :2].max(0)))

    def test_picture_hangs_1mm_in_front_of_the_wall(self):
        scene, objs = self.build("picture_on_wall")
        picture = world_polygons(objs["Picture"])
        wall = world_polygons(objs["Wall.Back"])
        self.assertAlmostEqual(wall[0][0, 1] - picture[0][0, 1], 1e-3, places=6)
        np.testing.assert_allclose(picture[1], wall[1], atol=1e-9)   # both facing into the room


if __name__ == "__main__":
    unittest.main()
