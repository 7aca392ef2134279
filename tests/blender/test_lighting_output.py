"""Lighting-only output (issue 15): the refined result with the objects' own materials.

- A textured room (checker image textures feeding Diffuse BSDFs on three walls
  and the floor, the floor's through a UV Map node naming its second UV map,
  "Tiles"), lit by an area light, solved with output 'LIGHTING' and rendered
  with Cycles, against a path trace of the original scene: mean luminance
  within 3 % (signed exposure error), median 8 x 8-block error within 6 %
  (image_agreement.py, emitter pixels left out), and the texture kept: the
  correlation of the two images' texture detail (each pixel's luminance over
  its 8 x 8 block's mean, where the lighting is nearly constant) over the
  textured region is high, and so is the checker contrast's agreement. The
  path trace is cached under <build>/lighting_cache (as test_contact.py's).
  "[agreement]" lines print the numbers (run_tests -v).
- The refined meshes carry the originals' UV maps under their names, with
  the values Blender interpolates there (the room's UVs are affine in position).
- The originals (objects, meshes, materials, images) are untouched after the
  solve, and after Remove; no lighting copy is left behind.
- "Radiosity Light" is H: "Radiosity" = emission + reflectance x H at every
  vertex of an untextured scene (the bundled cube), in every output mode that
  writes refined meshes.
"""

import hashlib
import json
import os
import pathlib
import sys
import unittest

import bpy
import numpy as np

import image_agreement
import render_compare as rc
from radiosity import compat
from radiosity.read import export
from radiosity.write import bake, bake_materials, result_state

ROOT = pathlib.Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "scenes"))
import build_scene  # noqa: E402
import scene_kit as kit  # noqa: E402

MEAN_TOLERANCE = 0.03
BLOCK_TOLERANCE = 0.06
NOISE_FRACTION = 0.25
# Texture detail correlation between solution and path trace over the textured
# pixels, and the checker contrast (bright cells over dark) within this of the path trace's.
CORRELATION_MIN = 0.9
CONTRAST_TOLERANCE = 0.05

RESOLUTION = (128, 128)
REFERENCE_SAMPLES = 128
MAX_SEEDS = 8
NOISE_TARGET = dict(exposure=0.003, block=0.01)
MASK_SAMPLES = 16
# The solution has no noise of its own, but its textures' edges need anti-aliasing
# like the reference's.
SOLUTION_SAMPLES = 32
RENDER_VERSION = 1

ROOM_LO, ROOM_HI = (-1.5, -1.5, 0.0), (1.5, 1.5, 2.5)
CELLS_PER_METRE = 2.0 / 0.75     # a 2 x 2-pixel checker repeated: cells of 0.375 m
TEXTURED = ("Wall.Left", "Wall.Right", "Wall.Back", "Floor")


# --- The textured room ---------------------------------------------------------------------

def linear_to_srgb(c):
    c = np.asarray(c, dtype=np.float64)
    return np.where(c <= 0.0031308, 12.92 * c, 1.055 * c ** (1 / 2.4) - 0.055)


def checker_image(name, bright, dark):
    """A packed 2 x 2 sRGB byte image: bright and dark cells (linear RGB)."""
    image = bpy.data.images.new(name, 2, 2, alpha=False)
    b, d = (list(linear_to_srgb(c)) + [1.0] for c in (bright, dark))
    image.pixels.foreach_set(np.array([b, d, d, b], dtype=np.float32).ravel())
    image.pack()
    return image


def textured_material(name, image, uv_map=None):
    """A Diffuse BSDF whose Color is an image texture (closest pixel: crisp cells),
    through a UV Map node naming `uv_map` if given."""
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    tex = nodes.new("ShaderNodeTexImage")
    tex.image = image
    tex.interpolation = 'Closest'
    if uv_map:
        uv = nodes.new("ShaderNodeUVMap")
        uv.uv_map = uv_map
        links.new(uv.outputs["UV"], tex.inputs["Vector"])
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    output = nodes.new("ShaderNodeOutputMaterial")
    links.new(tex.outputs["Color"], bsdf.inputs["Color"])
    links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    return mat


def planar_uv(points, origin, u, v, scale):
    """UVs of points on the plane origin + s u + t v: (s |u|, t |v|) x scale (affine)."""
    d = np.asarray(points, dtype=np.float64) - origin
    return np.column_stack([d @ u / np.linalg.norm(u), d @ v / np.linalg.norm(v)]) * scale


def add_uv_map(obj, name, scale):
    """A UV map of a one-quad object: its plane's coordinates times `scale`."""
    mesh = obj.data
    co = np.array([v.co[:] for v in mesh.vertices])
    origin, u, v = co[0], co[1] - co[0], co[3] - co[0]
    layer = mesh.uv_layers.new(name=name)
    loops = [mesh.loops[i].vertex_index for i in range(len(mesh.loops))]
    values = planar_uv(co[loops], origin, u, v, scale)
    compat.set_uv_layer(layer, values)
    obj["uv_frame"] = json.dumps([origin.tolist(), u.tolist(), v.tolist()])
    return layer


def build_textured_room(scene):
    wallpaper = checker_image("Wallpaper", (0.75, 0.65, 0.45), (0.12, 0.18, 0.3))
    tiles = checker_image("Tiles", (0.7, 0.7, 0.7), (0.08, 0.08, 0.08))
    paper = textured_material("Wallpaper", wallpaper)
    materials = {name: paper for name in TEXTURED[:3]}
    materials["Floor"] = textured_material("Floor Tiles", tiles, uv_map="Tiles")
    white = kit.lambertian_material("White", (0.7, 0.7, 0.7))
    for name, geometry in kit.room_walls(ROOM_LO, ROOM_HI).items():
        obj = kit.add_mesh(scene, name, geometry, materials.get(name, white))
        if name in TEXTURED:
            # The render UV map "UVMap" (the walls' texture coordinates); the floor
            # also has "Tiles", at another scale, which its material names.
            add_uv_map(obj, "UVMap", CELLS_PER_METRE / 2)
            if name == "Floor":
                add_uv_map(obj, "Tiles", CELLS_PER_METRE / 2 * 1.5)
                obj.data.uv_layers["UVMap"].active_render = True
    light = bpy.data.lights.new("Area", 'AREA')
    light.shape = 'RECTANGLE'
    light.size, light.size_y = 0.6, 0.5
    light.energy = 30.0
    obj = bpy.data.objects.new("Area", light)
    # Above the camera, out of its view (Cycles does not show an area light to
    # the camera; the solution's light polygon would be seen).
    obj.location = (1.0, -1.0, 2.4)
    scene.collection.objects.link(obj)
    kit.add_camera(scene, location=(1.2, -1.3, 1.5), target=(-0.6, 0.8, 0.5), lens=14.0)
    kit.setup_render(scene, resolution=RESOLUTION)


def textured_room():
    scene = kit.empty_file()
    scene.name = "textured_room"
    build_textured_room(scene)
    scene.view_layers[0].update()
    return scene


# --- Reference, cached --------------------------------------------------------------------

def build_dir():
    import radiosity
    return pathlib.Path(radiosity.__file__).resolve().parents[2]


def cache_path(tag, samples):
    h = hashlib.sha256()
    source = pathlib.Path(__file__).read_text()
    # Only the scene's part of this file: changing a tolerance renders nothing again.
    h.update(source[source.index("# --- The textured room"):source.index("# --- Reference, cached")].encode())
    h.update((ROOT / "scenes" / "scene_kit.py").read_bytes())
    h.update(json.dumps([RESOLUTION, samples, tag, bpy.app.version_string, RENDER_VERSION]).encode())
    return build_dir() / "lighting_cache" / ("textured_room_%s.npy" % h.hexdigest()[:16])


def cached(path, render):
    if path.exists():
        return np.load(path), True
    image = render()
    path.parent.mkdir(parents=True, exist_ok=True)
    np.save(path, image)
    return image, False


def reference(scene):
    """(mean image, mask, noise dict, seeds, rendered count): the path trace of the originals."""
    mask, hit = cached(cache_path("mask", MASK_SAMPLES), lambda: rc.emitter_mask(scene, MASK_SAMPLES, RESOLUTION))
    seeds, rendered = [], int(not hit)
    noise = None
    for seed in range(1, MAX_SEEDS + 1):
        image, hit = cached(cache_path(seed, REFERENCE_SAMPLES),
                            lambda: rc.render_image(scene, REFERENCE_SAMPLES, RESOLUTION, seed=seed))
        seeds.append(image)
        rendered += not hit
        if seed % 2 == 0:
            half = len(seeds) // 2
            e = image_agreement.compare(np.mean(seeds[:half], axis=0), np.mean(seeds[half:], axis=0), mask)
            noise = dict(exposure=abs(e["exposure"]) / 2, block=e["block"] / 2)
            if all(noise[k] <= NOISE_TARGET[k] for k in noise):
                break
    return np.mean(seeds, axis=0), mask, noise, len(seeds), rendered


def object_mask(scene, names, samples=4):
    """(H, W) bool: the pixels where the named objects are seen: every other object
    hidden, the named ones lit directly by a white world, the background transparent."""
    others = [o for o in scene.objects if o.name not in names and not o.hide_render and o.type != 'CAMERA']
    world = scene.world.node_tree.nodes["Background"].inputs["Color"]
    colour, transparent, bounces = tuple(world.default_value), scene.render.film_transparent, scene.cycles.max_bounces
    for obj in others:
        obj.hide_render = True
    world.default_value = (1.0, 1.0, 1.0, 1.0)
    scene.render.film_transparent = True
    scene.cycles.max_bounces = 0
    try:
        image = rc.render_image(scene, samples, RESOLUTION, seed=0)
    finally:
        for obj in others:
            obj.hide_render = False
        world.default_value = colour
        scene.render.film_transparent = transparent
        scene.cycles.max_bounces = bounces
    return image.max(axis=2) > 1e-3


def texture_numbers(image, ref, keep):
    """(correlation of texture detail, checker contrast over the reference's) over `keep`:
    detail = luminance over its 8 x 8 block's mean (of kept pixels)."""
    def detail(img):
        lum = image_agreement.luminance(img)
        means, _ = image_agreement.block_means(lum, keep)
        h, w = lum.shape
        up = np.repeat(np.repeat(means, 8, axis=0), 8, axis=1)
        d = np.full(lum.shape, np.nan)
        d[:up.shape[0], :up.shape[1]] = lum[:up.shape[0], :up.shape[1]] / np.maximum(up, 1e-9)
        return d, lum

    da, la = detail(image)
    db, lb = detail(ref)
    sel = keep & np.isfinite(da) & np.isfinite(db)
    correlation = float(np.corrcoef(da[sel], db[sel])[0, 1])
    bright, dark = sel & (db > 1.0), sel & (db < 1.0)
    contrast = (la[bright].mean() / la[dark].mean()) / (lb[bright].mean() / lb[dark].mean())
    return correlation, float(contrast), int(sel.sum())


class TexturedRoomAgreementTest(unittest.TestCase):
    def test_lighting_only_matches_path_trace(self):
        scene = textured_room()
        ref, mask, noise, seeds, rendered = reference(scene)
        textured, hit = cached(cache_path("textured", 4), lambda: object_mask(scene, set(TEXTURED)))
        print("[agreement] textured_room reference: %d seeds x %d samples%s; its noise: exposure %.2f %%, "
              "median block %.2f %%; emitter pixels left out %.1f %%, textured pixels %.1f %%"
              % (seeds, REFERENCE_SAMPLES, "" if rendered else " (cached)", 100 * noise["exposure"],
                 100 * noise["block"], 100 * mask.mean(), 100 * textured.mean()), flush=True)
        self.assertLess(noise["exposure"], NOISE_FRACTION * MEAN_TOLERANCE)
        self.assertLess(noise["block"], NOISE_FRACTION * BLOCK_TOLERANCE)
        self.assertGreater(textured.mean(), 0.3)

        scene.radiosity.output = 'LIGHTING'
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        stats = scene.radiosity.stats
        image = rc.render_image(scene, SOLUTION_SAMPLES, RESOLUTION, seed=0)
        e = image_agreement.compare(image, ref, mask)
        correlation, contrast, pixels = texture_numbers(image, ref, textured & ~mask)
        # The same without textures (output Refined Meshes) has no texture detail:
        # the correlation measures the textures, not the lighting.
        scene.radiosity.output = 'REFINED'
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        plain = rc.render_image(scene, 8, RESOLUTION, seed=0)
        plain_correlation, _, _ = texture_numbers(plain, ref, textured & ~mask)
        numbers = ("textured_room lighting-only (Blender %s): exposure %+.1f %% (tolerance %.0f %%), median block "
                   "error %.1f %% (tolerance %.0f %%, %d blocks), texture detail correlation %.3f (min %.2f; "
                   "untextured Refined Meshes: %.3f) over %d pixels, checker contrast / path trace's %.3f "
                   "(tolerance %.0f %%); %d elements, %s"
                   % (bpy.app.version_string, 100 * e["exposure"], 100 * MEAN_TOLERANCE, 100 * e["block"],
                      100 * BLOCK_TOLERANCE, e["blocks"], correlation, CORRELATION_MIN, plain_correlation, pixels,
                      contrast, 100 * CONTRAST_TOLERANCE, stats.elements, stats.status))
        print("[agreement] " + numbers, flush=True)
        folder = os.environ.get("RADIOSITY_TEST_IMAGES")
        if folder:
            os.makedirs(folder, exist_ok=True)
            rc.save_png(ref, os.path.join(folder, "textured_room_cycles.png"))
            rc.save_png(image, os.path.join(folder, "textured_room_lighting.png"))
            rc.save_png(plain, os.path.join(folder, "textured_room_refined.png"))
        self.assertLess(abs(e["exposure"]), MEAN_TOLERANCE, numbers)
        self.assertLess(e["block"], BLOCK_TOLERANCE, numbers)
        self.assertGreater(correlation, CORRELATION_MIN, numbers)
        self.assertLess(abs(contrast - 1.0), CONTRAST_TOLERANCE, numbers)
        self.assertLess(plain_correlation, 0.5, numbers)


# --- What the bake writes -----------------------------------------------------------------

def colour_values(mesh, name):
    attr = mesh.color_attributes[name]
    values = np.empty(4 * len(attr.data), dtype=np.float32)
    attr.data.foreach_get("color", values)
    return values.reshape(-1, 4)[:, :3]


def uv_values(mesh, name):
    return compat.get_uv_layer(mesh.uv_layers[name], len(mesh.loops))


def socket_value(socket):
    value = getattr(socket, "default_value", None)
    if value is None:
        return None
    try:
        return tuple(round(float(x), 7) for x in value)
    except TypeError:
        return value if isinstance(value, str) else round(float(value), 7)


def originals_snapshot(scene):
    """Everything of the original objects, meshes, materials and images a bake could touch."""
    data = {}
    for obj in scene.objects:
        if obj.get(result_state.RESULT_TAG):
            continue
        entry = {"matrix": [tuple(r) for r in obj.matrix_world], "data": obj.data.name if obj.data else None,
                 "slots": [(s.link, s.material.name if s.material else None) for s in obj.material_slots],
                 "keys": sorted(k for k in obj.keys() if k != result_state.HIDDEN_TAG),
                 "hidden": (obj.hide_render, obj.hide_viewport, obj.hide_get())}
        if obj.type == 'MESH':
            mesh = obj.data
            co = np.empty(3 * len(mesh.vertices))
            mesh.vertices.foreach_get("co", co)
            entry["mesh"] = (hashlib.sha1(co.tobytes()).hexdigest(), len(mesh.polygons), len(mesh.loops),
                             sorted(a.name for a in mesh.attributes),
                             [(layer.name, layer.active_render, hashlib.sha1(uv_values(mesh, layer.name).tobytes())
                               .hexdigest()) for layer in mesh.uv_layers],
                             [m.name if m else None for m in mesh.materials])
        data[obj.name] = entry
    for mat in bpy.data.materials:
        if mat.get(bake_materials.COPY_TAG) is not None or mat.get(result_state.MATERIAL_TAG):
            continue
        entry = {"use_nodes": mat.use_nodes, "diffuse": tuple(mat.diffuse_color), "users": mat.users,
                 "keys": sorted(mat.keys()), "backface": mat.use_backface_culling}
        if mat.node_tree is not None:
            entry["nodes"] = sorted((n.name, n.bl_idname, n.mute, tuple(n.location),
                                     tuple((s.identifier, socket_value(s)) for s in n.inputs))
                                    for n in mat.node_tree.nodes)
            entry["links"] = sorted((l.from_node.name, l.from_socket.identifier, l.to_node.name,
                                     l.to_socket.identifier) for l in mat.node_tree.links)
        data["material " + mat.name] = entry
    for image in bpy.data.images:
        pixels = np.empty(len(image.pixels), dtype=np.float32)
        image.pixels.foreach_get(pixels)
        data["image " + image.name] = (hashlib.sha1(pixels.tobytes()).hexdigest(), image.packed_file is not None)
    return data


def without_hidden(snapshot):
    return {k: ({kk: vv for kk, vv in v.items() if kk != "hidden"} if isinstance(v, dict) else v)
            for k, v in snapshot.items()}


class LightingBakeTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        # One solve of the textured room, at a low quality (the bake is what is tested).
        cls.scene = textured_room()
        # A Principled material with emission and an object without material:
        # they are converted too.
        principled = kit.diffuse_material("Principled Glow", (0.3, 0.5, 0.2))
        node = principled.node_tree.nodes["Principled BSDF"]
        kit.principled_input(node, "Emission").default_value = (1.0, 0.5, 0.25, 1.0)
        node.inputs["Emission Strength"].default_value = 0.2
        kit.add_mesh(cls.scene, "Glow box", kit.box((0.3, 0.3, 0.3)), principled, location=(-0.5, 0.6, 0.6))
        bare = kit.add_mesh(cls.scene, "Bare box", kit.box((0.2, 0.2, 0.2)), white_placeholder(),
                            location=(0.6, 0.6, 0.3))
        bare.data.materials.clear()
        add_sign(cls.scene, principled)
        cls.scene.view_layers[0].update()
        cls.before = originals_snapshot(cls.scene)
        cls.scene.radiosity.output = 'LIGHTING'
        cls.scene.radiosity.quality = 0.2
        cls.status = bpy.ops.radiosity.solve()
        cls.after_solve = originals_snapshot(cls.scene)

    @property
    def results(self):
        return {o[result_state.RESULT_TAG]: o for o in result_state.result_objects(self.scene)}

    def test_solved(self):
        self.assertEqual(self.status, {'FINISHED'})
        self.assertTrue({"Floor", "Wall.Left", "Glow box", "Bare box", "Area"} <= set(self.results))

    def test_originals_untouched_by_the_solve(self):
        self.assertEqual(without_hidden(self.after_solve), without_hidden(self.before))
        for name in TEXTURED:
            self.assertTrue(self.scene.objects[name].hide_render)   # hidden while the result shows

    def test_results_use_lighting_copies(self):
        for source, obj in self.results.items():
            original = self.scene.objects[source]
            with self.subTest(object=source):
                if original.type == 'LIGHT':
                    self.assertEqual([m.name for m in obj.data.materials], [bake.MATERIAL_NAME])
                    continue
                copies = [m for m in obj.data.materials if m is not None]
                self.assertTrue(copies)
                for mat in copies:
                    tag = mat.get(bake_materials.COPY_TAG)
                    self.assertIsNotNone(tag)
                    originals = [s.material.name if s.material else "" for s in original.material_slots] or [""]
                    self.assertIn(tag, originals)
                    kinds = {n.type for n in mat.node_tree.nodes}
                    self.assertFalse(kinds & {'BSDF_DIFFUSE', 'BSDF_PRINCIPLED'}, kinds)
                    self.assertIn('EMISSION', kinds)
                    self.assertTrue(any(n.type == 'ATTRIBUTE' and n.attribute_name == bake_materials.LIGHT_ATTRIBUTE
                                        for n in mat.node_tree.nodes))
                    self.assertTrue(mat.use_backface_culling)
        # The textured copies still read their images, through the same UV map names.
        floor = self.results["Floor"].data.materials[0]
        kinds = {n.type: n for n in floor.node_tree.nodes}
        self.assertEqual(kinds['TEX_IMAGE'].image.name, "Tiles")
        self.assertEqual(kinds['UVMAP'].uv_map, "Tiles")
        # The Principled BSDF's emission is kept: a vector SCALE by its strength.
        glow = self.results["Glow box"].data.materials[0]
        scales = [n for n in glow.node_tree.nodes if n.type == 'VECT_MATH' and n.operation == 'SCALE']
        self.assertEqual(len(scales), 1)
        self.assertAlmostEqual(scales[0].inputs[3].default_value, 0.2, places=6)

    def test_uv_maps_carried_with_their_values(self):
        for name in TEXTURED:
            original = self.scene.objects[name]
            mesh = self.results[name].data
            with self.subTest(object=name):
                self.assertEqual([l.name for l in mesh.uv_layers], [l.name for l in original.data.uv_layers])
                self.assertEqual([l.active_render for l in mesh.uv_layers],
                                 [l.active_render for l in original.data.uv_layers])
                co = np.empty(3 * len(mesh.vertices))
                mesh.vertices.foreach_get("co", co)
                loops = np.empty(len(mesh.loops), dtype=np.int64)
                mesh.loops.foreach_get("vertex_index", loops)
                origin, u, v = (np.array(x) for x in json.loads(original["uv_frame"]))
                points = co.reshape(-1, 3)[loops]
                self.assertGreater(len(points), 8)   # refined
                for layer, scale in (("UVMap", CELLS_PER_METRE / 2), ("Tiles", CELLS_PER_METRE / 2 * 1.5)):
                    if layer in mesh.uv_layers:
                        # Exact up to the float32 UVs and the sides' 4 um offset (along the normal).
                        np.testing.assert_allclose(uv_values(mesh, layer), planar_uv(points, origin, u, v, scale),
                                                   atol=1e-4)

    def test_uv_maps_follow_blenders_triangles_mirrored(self):
        # Random UVs per corner are linear only over each of Blender's loop
        # triangles: the result must take them from the triangle it lies in,
        # also for an n-gon and through a mirroring transform.
        sign = self.scene.objects["Sign"]
        mesh = self.results["Sign"].data
        points, uv = corner_points_and_uvs(mesh, "UVMap")
        expected = blender_uvs_at(sign, "UVMap", points)
        corners = np.array([sign.matrix_world @ v.co for v in sign.data.vertices])
        inside = np.linalg.norm(points[:, None] - corners[None], axis=2).min(axis=1) > 0.01
        self.assertGreater(inside.sum(), 20)     # refined: points inside the faces
        self.assertFalse(np.isnan(expected).any())
        np.testing.assert_allclose(uv, expected, atol=2e-4)

    def test_originals_untouched_after_clear(self):
        scene = self.scene
        self.assertEqual(bpy.ops.radiosity.clear(), {'FINISHED'})
        self.assertEqual(originals_snapshot(scene), self.before)
        self.assertFalse(result_state.result_objects(scene))
        self.assertFalse([m.name for m in bpy.data.materials if m.get(bake_materials.COPY_TAG) is not None])
        # Solve again afterwards: the copies come back under their names.
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        names = sorted(m.name for m in bpy.data.materials if m.get(bake_materials.COPY_TAG) is not None)
        self.assertIn("Wallpaper" + bake_materials.SUFFIX, names)
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})   # a re-solve keeps the names
        self.assertEqual(sorted(m.name for m in bpy.data.materials if m.get(bake_materials.COPY_TAG) is not None),
                         names)


def add_sign(scene, material):
    """"Sign": a quad and, apart from it, a hexagon (an n-gon) with random UVs per
    corner, floating under the light, mirrored (scale -1 in x)."""
    hexagon = [(0.25 + 0.15 * np.cos(a), 0.15 * np.sin(a), 0.0) for a in np.linspace(0, 2 * np.pi, 6, endpoint=False)]
    quad = [(-0.4, -0.15, 0.0), (-0.05, -0.2, 0.0), (-0.1, 0.15, 0.0), (-0.35, 0.1, 0.0)]
    mesh = bpy.data.meshes.new("Sign")
    mesh.from_pydata(quad + hexagon, [], [list(range(4)), list(range(4, 10))])
    mesh.materials.append(material)
    layer = mesh.uv_layers.new(name="UVMap")
    rng = np.random.default_rng(7)
    compat.set_uv_layer(layer, rng.uniform(0, 1, (len(mesh.loops), 2)))
    obj = bpy.data.objects.new("Sign", mesh)
    # Close under the light, tilted: its light varies, so it is refined.
    obj.location = (0.8, -0.7, 1.9)
    obj.scale = (-1.5, 1.5, 1.5)
    obj.rotation_euler = (0.3, 0.0, 0.4)
    scene.collection.objects.link(obj)
    return obj


def corner_points_and_uvs(mesh, name):
    """(C, 3) positions of a result mesh's corners and their (C, 2) UVs."""
    co = np.empty(3 * len(mesh.vertices))
    mesh.vertices.foreach_get("co", co)
    loops = np.empty(len(mesh.loops), dtype=np.int64)
    mesh.loops.foreach_get("vertex_index", loops)
    return co.reshape(-1, 3)[loops], uv_values(mesh, name)


def blender_uvs_at(obj, name, points, tolerance=1e-4):
    """UVs of `obj` at world points as Blender interpolates them: over the mesh's
    loop triangles (read here straight from Blender), the triangle containing the point."""
    mesh = obj.data
    mesh.calc_loop_triangles() if hasattr(mesh, "calc_loop_triangles") else None
    world = np.array(obj.matrix_world)
    co = np.array([(world @ np.append(v.co[:], 1.0))[:3] for v in mesh.vertices])
    uv = uv_values(mesh, name)
    out = np.full((len(points), 2), np.nan)
    best = np.full(len(points), -np.inf)
    for tri in mesh.loop_triangles:
        loops = list(tri.loops)
        a, b, c = (co[mesh.loops[i].vertex_index] for i in loops)
        n = np.cross(b - a, c - a)
        n /= np.linalg.norm(n)
        on_plane = np.abs((points - a) @ n) < tolerance
        m = np.column_stack([b - a, c - a])
        st = np.linalg.lstsq(m, (points - a).T, rcond=None)[0].T
        w = np.column_stack([1 - st.sum(axis=1), st])
        score = np.where(on_plane, w.min(axis=1), -np.inf)
        better = score > np.maximum(best, -tolerance)
        out[better] = w[better] @ uv[loops]
        best = np.maximum(best, score)
    return out


def white_placeholder():
    return kit.lambertian_material("Placeholder", (0.5, 0.5, 0.5))


class LightAttributeTest(unittest.TestCase):
    def check(self, output):
        bpy.ops.wm.read_homefile(use_empty=True)
        scene = bpy.context.scene
        build_scene.build("cube", scene)
        scene.radiosity.output = output
        scene.radiosity.quality = 0.3
        self.assertEqual(bpy.ops.radiosity.solve(), {'FINISHED'})
        reader = export.MaterialReader()
        checked = 0
        for obj in result_state.result_objects(scene):
            original = scene.objects[obj[result_state.RESULT_TAG]]
            mesh = obj.data
            light = mesh.color_attributes[bake_materials.LIGHT_ATTRIBUTE]
            self.assertEqual((light.data_type, light.domain), ('FLOAT_COLOR', 'POINT'))
            # "Radiosity" stays the active and rendered colour.
            names = [a.name for a in mesh.color_attributes]
            self.assertEqual(names[mesh.color_attributes.render_color_index], "Radiosity")
            self.assertEqual(mesh.color_attributes.active_color.name, "Radiosity")
            radiance, h = colour_values(mesh, "Radiosity"), colour_values(mesh, bake_materials.LIGHT_ATTRIBUTE)
            self.assertTrue(np.all(h >= 0) and np.all(np.isfinite(h)))
            if original.type != 'MESH' or len(original.material_slots) != 1:
                continue
            rho, emission = reader.read(original.material_slots[0].material)
            expected = emission + rho * h
            with self.subTest(object=original.name, output=output):
                np.testing.assert_allclose(radiance, expected, rtol=2e-5, atol=1e-6 * max(radiance.max(), 1.0))
            checked += 1
            if rho.max() > 0:
                self.assertGreater(h.max(), 0.0)
        self.assertGreater(checked, 5)

    def test_radiance_is_emission_plus_reflectance_times_light(self):
        self.check('LIGHTING')

    def test_refined_meshes_carry_the_light_too(self):
        self.check('REFINED')


if __name__ == "__main__":
    unittest.main()
