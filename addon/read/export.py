"""Reads a Blender scene into the solver's arrays (Blender glue; the array work is arrays.py).

What is exported, as a Cycles render would see it:
- every mesh-like object a render shows (render_visibility.py: viewport-hidden
  ones too, not those disabled in renders) of the evaluated depsgraph (modifiers
  applied), including instances (collection instances, geometry-node and particle
  instances), in world space; polygons as they are (the solver keeps planar quads
  and triangulates the rest), but faces with a NaN or Inf coordinate left out;
- per face, the material's diffuse reflectance (Principled BSDF Base Color,
  Diffuse BSDF Color, the average of an image texture feeding either, magenta for
  one without pixels as in Cycles, else the viewport colour) and emitted radiance (Emission colour x strength of a
  Principled BSDF or an Emission shader);
- per face corner the UV maps, and each face's loop triangles (how Blender
  renders it), for the UV maps of the refined result (surface_uv.py);
- area lights as one-sided emitting polygons (rectangle, square, disk, ellipse)
  that cast no shadow (Cycles lets light through a light object: measured)
  with Blender's power-to-radiance conversion (arrays.area_light_radiance);
- point, spot and sun lights as the solver's direct lights, and a uniform world
  colour (Background colour x strength) as the world's radiance, each with
  Blender's conventions measured in Cycles (light_units.py).
What is not modelled (node setups other than the above, light node setups,
textured worlds) or only approximated (a Principled BSDF's metallic or
transmission read as diffuse, an emission texture's average) is collected in
`ExportedScene.unmodelled` for one warning; what was left out or replaced
(non-finite faces, missing images) in `ExportedScene.repaired`.
"""

import math
from dataclasses import dataclass, field

import bpy
import numpy as np

from .. import compat
from ..model import arrays, closed_volumes, light_units, surface_uv
from ..write.result_state import HIDDEN_TAG, RESULT_TAG
from . import render_visibility

GEOMETRY_TYPES = {'MESH', 'CURVE', 'SURFACE', 'FONT', 'META'}
DEFAULT_REFLECTANCE = (0.8, 0.8, 0.8)  # a face without material renders as grey 0.8 diffuse
# What Cycles renders for an Image Texture without pixels (no image, a missing or
# unreadable file): magenta, measured in 3.4, 4.5 and 5.0.
MISSING_IMAGE = (1.0, 0.0, 1.0)


@dataclass
class Part:
    """One exported object instance or light: where its faces came from."""
    name: str                 # name of the result object
    source: str               # name of the original object (or light object)
    is_instance: bool
    is_light: bool
    face_count: int
    corner_points: np.ndarray = None   # (C, 3) world positions of its faces' corners
    face_sizes: np.ndarray = None      # (F,) corners per face
    materials: list = field(default_factory=list)  # material per face slot (None for none)
    material_index: np.ndarray = None  # (F,) slot of each face
    # UV maps per corner of its faces (same order as corner_points), {name: (C, 2)},
    # the render UV map's name, and the faces' triangles as Blender renders them
    # ((T, 3) corner indices, (T,) face of each): surface_uv.py.
    uv_layers: dict = field(default_factory=dict)
    uv_render: str = ""
    triangles: np.ndarray = None
    triangle_face: np.ndarray = None
    # The evaluated mesh's polygons exported (None: all of them, in order), and
    # how many it has: faces with non-finite coordinates are left out.
    polygons: np.ndarray = None
    polygon_count: int = 0
    # Whether Cycles shows it to the camera (Object > Visibility > Ray Visibility >
    # Camera; off by default for lights, so an area light in view renders black):
    # its result object shows it or not the same way.
    camera_visible: bool = True


@dataclass
class ExportedScene:
    arrays: dict
    parts: list
    unmodelled: list          # human-readable descriptions of what was not modelled
    hidden_sources: list      # names of original objects whose render visibility the bake may toggle
    lights: list = field(default_factory=list)  # point, spot and sun lights in the solver's form
    world: np.ndarray = None  # radiance of a uniform world, or None for black
    # Input the export could not use as it is and what it did instead, for the warning.
    repaired: list = field(default_factory=list)

    @property
    def face_count(self):
        return len(self.arrays["face_sizes"])


class MaterialReader:
    """Reflectance and emission of materials, cached; records what it could not read."""

    def __init__(self):
        self._cache = {}
        self._images = {}
        self.unknown = set()
        self.missing_images = set()  # "name (file)" of images without pixels
        # What was read but only approximated: reason -> material names.
        self.approximated = {}

    def _approximate(self, material, reason):
        self.approximated.setdefault(reason, set()).add(material.name)

    def read(self, material):
        """(reflectance rgb, emission rgb) of `material` (None: default surface)."""
        if material is None:
            return np.array(DEFAULT_REFLECTANCE), np.zeros(3)
        key = material.name_full
        if key not in self._cache:
            self._cache[key] = self._read(material)
        return self._cache[key]

    def _read(self, material):
        viewport = np.array(material.diffuse_color[:3], dtype=float)
        if not material.use_nodes or material.node_tree is None:
            return viewport, np.zeros(3)
        output = _active_output(material.node_tree)
        if output is None or not output.inputs["Surface"].is_linked:
            # Cycles renders a material without surface as black.
            return np.zeros(3), np.zeros(3)
        result = self._shader(_linked_node(output.inputs["Surface"]), material)
        if result is None:
            self.unknown.add(material.name)
            return viewport, np.zeros(3)
        return result

    def _shader(self, node, material):
        """(rho, emission) of a shader node, or None when it is not a known diffuse/emission setup."""
        if node is None:
            return np.zeros(3), np.zeros(3)
        kind = node.type
        if kind == 'BSDF_PRINCIPLED':
            rho = self._colour(node.inputs["Base Color"], material)
            emission = self._emission_colour(compat.principled_emission(node), material)
            strength = _scalar(node.inputs.get("Emission Strength"), 1.0)
            if rho is None or emission is None or strength is None:
                return None
            # Cycles renders these lobes; the solver sees the surface as diffuse.
            for name in ("Metallic", "Transmission Weight", "Transmission"):
                socket = node.inputs.get(name)
                if socket is not None and (socket.is_linked or socket.default_value > 0.0):
                    self._approximate(material, "%s read as diffuse" % name.split()[0].lower())
            return rho, emission * strength
        if kind == 'BSDF_DIFFUSE':
            rho = self._colour(node.inputs["Color"], material)
            return None if rho is None else (rho, np.zeros(3))
        if kind == 'EMISSION':
            colour = self._emission_colour(node.inputs["Color"], material)
            strength = _scalar(node.inputs["Strength"], 1.0)
            if colour is None or strength is None:
                return None
            return np.zeros(3), colour * strength
        if kind == 'ADD_SHADER':
            a, b = (self._shader(_linked_node(s), material) for s in node.inputs[:2])
            if a is None or b is None:
                return None
            return a[0] + b[0], a[1] + b[1]
        if kind == 'MIX_SHADER':
            fac = _scalar(node.inputs[0], None)
            a, b = (self._shader(_linked_node(s), material) for s in node.inputs[1:3])
            if fac is None or a is None or b is None:
                return None
            return (1 - fac) * a[0] + fac * b[0], (1 - fac) * a[1] + fac * b[1]
        return None

    def _colour(self, socket, material):
        """Linear RGB of a colour input: its value, an RGB node's, or an image's average."""
        if not socket.is_linked:
            return np.array(socket.default_value[:3], dtype=float)
        node = _linked_node(socket)
        if node is None:
            return np.zeros(3)
        if node.type == 'RGB':
            return np.array(node.outputs[0].default_value[:3], dtype=float)
        if node.type == 'TEX_IMAGE':
            return self._image_colour(node.image)
        return None

    def _emission_colour(self, socket, material):
        """An emission colour: as _colour, and an image feeding it is named, since
        its average (not the pattern) is what emits."""
        node = _linked_node(socket) if socket.is_linked else None
        if node is not None and node.type == 'TEX_IMAGE':
            self._approximate(material, "emission texture averaged")
        return self._colour(socket, material)

    def _image_colour(self, image):
        """An image's average; for a node without image or an image without pixels
        (file missing or unreadable), what Cycles renders: magenta, named in the warning."""
        if image is None:
            self.missing_images.add("(Image Texture without image)")
            return np.array(MISSING_IMAGE)
        key = image.name_full
        if key not in self._images:
            self._images[key] = _image_average(image)
        if self._images[key] is None:
            path = image.filepath
            self.missing_images.add("%s (%s)" % (image.name, path) if path else image.name)
            return np.array(MISSING_IMAGE)
        return self._images[key]


def _image_average(image):
    """Mean linear RGB of an image, or None if it has no pixels."""
    width, height = image.size  # (0, 0) when the file is missing or unreadable
    channels = image.channels
    if width * height == 0 or channels < 1:
        return None
    pixels = np.empty(width * height * channels, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    # A grey image (one or two channels) is its first channel in each of r, g, b.
    rgb = pixels.reshape(-1, channels)[:, [0, 1, 2] if channels >= 3 else [0, 0, 0]].astype(np.float64)
    # A float image's NaN or Inf pixels would make the whole surface so: left out.
    rgb = rgb[np.isfinite(rgb).all(axis=1)]
    if len(rgb) == 0:
        return None
    # Byte images hold their colour space's encoded values; float ones are linear.
    if not image.is_float and image.colorspace_settings.name == 'sRGB':
        rgb = arrays.srgb_to_linear(rgb)
    return rgb.mean(axis=0)


def _active_output(tree):
    outputs = [n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL' and n.target in {'ALL', 'CYCLES'}]
    for node in outputs:
        if node.is_active_output:
            return node
    return outputs[0] if outputs else None


def _linked_node(socket):
    """The node feeding `socket`, through reroutes; None if unlinked."""
    while socket.is_linked:
        link = socket.links[0]
        if not link.is_valid or link.is_muted:
            return None
        node = link.from_node
        if node.type != 'REROUTE':
            return None if node.mute else node
        socket = node.inputs[0]
    return None


def _scalar(socket, default):
    """An unlinked float input's value; None if linked (not modelled)."""
    if socket is None:
        return default
    if socket.is_linked:
        return None
    return float(socket.default_value)


def _mesh_arrays(obj_eval):
    """(positions (V,3) local, corners, face sizes, material index, surface_uv.LoopUVs
    or None) of an evaluated object."""
    mesh = obj_eval.to_mesh()
    try:
        nv, nl, npoly = len(mesh.vertices), len(mesh.loops), len(mesh.polygons)
        positions = np.empty(3 * nv)
        mesh.vertices.foreach_get("co", positions)
        loop_vertex = np.empty(nl, dtype=np.int32)
        mesh.loops.foreach_get("vertex_index", loop_vertex)
        loop_start = np.empty(npoly, dtype=np.int32)
        loop_total = np.empty(npoly, dtype=np.int32)
        material_index = np.empty(npoly, dtype=np.int32)
        mesh.polygons.foreach_get("loop_start", loop_start)
        mesh.polygons.foreach_get("loop_total", loop_total)
        mesh.polygons.foreach_get("material_index", material_index)
        uvs = _mesh_uvs(mesh, loop_start, loop_total)
    finally:
        obj_eval.to_mesh_clear()
    corners = arrays.polygon_corners(loop_start, loop_total, loop_vertex)
    return positions.reshape(-1, 3), corners, loop_total.astype(np.int64), material_index, uvs


def _mesh_uvs(mesh, loop_start, loop_total):
    """The UV maps and loop triangles of a mesh (surface_uv.LoopUVs), None without UV maps."""
    if len(mesh.uv_layers) == 0:
        return None
    layers = {layer.name: compat.get_uv_layer(layer, len(mesh.loops)) for layer in mesh.uv_layers}
    render = next((layer.name for layer in mesh.uv_layers if layer.active_render), mesh.uv_layers[0].name)
    if hasattr(mesh, "calc_loop_triangles"):
        mesh.calc_loop_triangles()
    count = len(mesh.loop_triangles)
    loops = np.empty(3 * count, dtype=np.int32)
    polygon = np.empty(count, dtype=np.int32)
    mesh.loop_triangles.foreach_get("loops", loops)
    mesh.loop_triangles.foreach_get("polygon_index", polygon)
    return surface_uv.LoopUVs(layers, render, loop_start, loop_total, loops, polygon)


def _renderable(obj):
    """An original object whose own flag lets a render show it (our own results excluded)."""
    if obj.get(RESULT_TAG):
        return False
    # Objects the add-on hid in renders are still part of the scene to solve.
    return not obj.hide_render or bool(obj.get(HIDDEN_TAG))


def rendered_shown(view_layer):
    """Context manager for the export: what a render shows is in the viewport's depsgraph."""
    return render_visibility.RenderedShown(view_layer, _renderable)


def export_scene(context, blender_version=None):
    """Read the scene of `context` into an ExportedScene: what a Cycles render of
    its view layer shows (inside rendered_shown, also what the viewport hides)."""
    depsgraph = context.evaluated_depsgraph_get()
    # Cycles leaves out what is disabled in renders, itself or by a collection.
    rendered = render_visibility.rendered_objects(context.view_layer, _renderable)
    version = tuple(blender_version or bpy.app.version)
    builder = arrays.SceneBuilder()
    reader = MaterialReader()
    parts = []
    lights_not_modelled = {}
    light_notes = set()
    direct_lights = []
    hidden_sources = set()
    names_used = {}
    non_finite = {}      # name -> (faces left out, faces), None for a light, where NaN or Inf coordinates

    for inst in depsgraph.object_instances:
        obj = inst.object
        original = obj.original
        owner = inst.parent.original if inst.is_instance and inst.parent else original
        if not _renderable(original) or owner not in rendered:
            continue
        if not (inst.show_self if inst.is_instance else True):
            continue
        matrix = np.array(inst.matrix_world, dtype=float)
        if obj.type == 'LIGHT':
            light = obj.data
            if not arrays.finite(matrix).all():
                non_finite[owner.name] = None
                continue
            if light.type != 'AREA':
                solver_light = _direct_light(light, matrix, version)
                if solver_light is None:
                    kind = light.type.lower()
                    lights_not_modelled[kind] = lights_not_modelled.get(kind, 0) + 1
                elif np.any(solver_light.get("intensity", solver_light.get("irradiance")) > 0):
                    direct_lights.append(solver_light)
                if light_nodes_change_it(light):
                    light_notes.add("light node setups")
                continue
            local, area = arrays.area_light_polygon(light.shape, light.size, light.size_y)
            area = arrays.scaled_area(matrix, area)
            if area <= 0.0 or light.energy <= 0.0:
                continue
            radiance = arrays.area_light_radiance(version, light.energy, area, compat.light_colour(light),
                                                  compat.light_exposure(light), compat.light_normalized(light))
            if getattr(light, "spread", math.pi) < math.pi - 1e-6:
                light_notes.add("area light spread")
            if light_nodes_change_it(light):
                light_notes.add("light node setups")
            points = arrays.transform_points(local, matrix)
            n = len(points)
            builder.add(points, np.arange(n), [n], [0.0, 0.0, 0.0], radiance, False, occludes=False)
            part = Part(name=_unique(names_used, original.name), source=owner.name,
                        is_instance=inst.is_instance, is_light=True, face_count=1,
                        corner_points=points, face_sizes=np.array([n]),
                        camera_visible=_camera_visible(original, owner))
            parts.append(part)
            hidden_sources.add(owner.name)
            continue
        if obj.type not in GEOMETRY_TYPES:
            continue
        positions, corners, sizes, material_index, uvs = _mesh_arrays(obj)
        if len(sizes) == 0:
            continue
        with np.errstate(invalid="ignore", over="ignore"):   # NaN and Inf are dealt with below
            world = arrays.transform_points(positions, matrix)
        # An Inf (a float's largest) rotated may come out finite: local coordinates count too.
        world[~arrays.finite(positions).all(axis=1)] = np.nan
        mirrored = np.linalg.det(matrix[:3, :3]) < 0
        if mirrored:
            # A mirroring transform flips the winding; keep normals as Blender shows them.
            corners = arrays.reverse_polygons(corners, sizes)
        name = original.name if not inst.is_instance else "%s (%s)" % (original.name, owner.name)
        # The solver refuses non-finite coordinates: faces using one are left out, and named.
        keep = arrays.finite_faces(world, corners, sizes)
        polygon_count, polygons, corner_keep = len(sizes), None, None
        if not keep.all():
            non_finite[name] = (int(np.count_nonzero(~keep)), polygon_count)
            if not keep.any():
                continue
            world, corners, sizes, corner_keep = arrays.keep_faces(world, corners, sizes, keep)
            polygons, material_index = np.flatnonzero(keep), material_index[keep]
        materials = [slot.material for slot in obj.material_slots] or [None]
        table = [reader.read(m) for m in materials]
        rho_table = np.array([t[0] for t in table])
        emit_table = np.array([t[1] for t in table])
        slot = np.clip(material_index, 0, len(materials) - 1)
        builder.add(world, corners, sizes, rho_table[slot], emit_table[slot], True)
        part = Part(name=_unique(names_used, name), source=owner.name,
                    is_instance=inst.is_instance, is_light=False, face_count=len(sizes),
                    corner_points=world[corners], face_sizes=sizes,
                    materials=materials, material_index=slot,
                    polygons=polygons, polygon_count=polygon_count,
                    camera_visible=_camera_visible(original, owner))
        if uvs is not None:
            part.uv_layers, part.triangles, part.triangle_face = uvs.corners(mirrored)
            part.uv_render = uvs.render
            if polygons is not None:
                _keep_uv_faces(part, keep, corner_keep)
        parts.append(part)
        hidden_sources.add(owner.name)

    repaired = []
    if non_finite:
        repaired.append("non-finite (NaN or Inf) coordinates, left out: " + ", ".join(
            _non_finite_text(name, non_finite[name]) for name in sorted(non_finite)))
    if reader.missing_images:
        names = sorted(reader.missing_images)
        repaired.append("image%s without pixels (file missing or unreadable) read as magenta, as Cycles "
                        "renders them: %s" % ("s" if len(names) > 1 else "", ", ".join(names)))
    unmodelled = []
    for kind in sorted(lights_not_modelled):
        count = lights_not_modelled[kind]
        unmodelled.append("%d %s light%s" % (count, kind, "s" if count > 1 else ""))
    if reader.unknown:
        unmodelled.append("material%s %s (unknown node setup: viewport colour used)"
                          % ("s" if len(reader.unknown) > 1 else "", ", ".join(sorted(reader.unknown))))
    for reason in sorted(reader.approximated):
        names = sorted(reader.approximated[reason])
        unmodelled.append("material%s %s (%s)" % ("s" if len(names) > 1 else "", ", ".join(names), reason))
    unmodelled.extend(sorted(light_notes))
    world, world_note = world_radiance(context.scene.world)
    if world_note:
        unmodelled.append(world_note)
    scene_arrays = builder.arrays()
    # Closed objects with nothing inside them (no light, no other object, not
    # the camera): their inside sides see only each other, in the dark.
    inside_points = [light["position"] for light in direct_lights if "position" in light]
    if context.scene.camera is not None:
        inside_points.append(np.array(context.scene.camera.matrix_world.translation, dtype=float))
    scene_arrays["two_sided"] &= ~closed_volumes.empty_closed_faces(scene_arrays, inside_points)
    return ExportedScene(arrays=scene_arrays, parts=parts, unmodelled=unmodelled,
                         hidden_sources=sorted(hidden_sources), lights=direct_lights, world=world,
                         repaired=repaired)


def _non_finite_text(name, counts):
    if counts is None:
        return "%s (a light)" % name
    skipped, total = counts
    if skipped == total:
        return "%s (all %d face%s)" % (name, total, "s" if total > 1 else "")
    return "%s (%d of %d faces)" % (name, skipped, total)


def _keep_uv_faces(part, keep, corner_keep):
    """A part's UV maps and triangles (surface_uv order) for its faces where `keep` only."""
    corner_map = np.cumsum(corner_keep) - 1
    face_map = np.cumsum(keep) - 1
    part.uv_layers = {n: uv[corner_keep] for n, uv in part.uv_layers.items()}
    kept = keep[part.triangle_face]
    part.triangles = corner_map[part.triangles[kept]]
    part.triangle_face = face_map[part.triangle_face[kept]]


def light_nodes_change_it(light):
    """Whether a light's node tree changes its light (not modelled): anything but
    the tree Blender 5.x gives every new light, a white Emission of strength 1
    into the Light Output, which renders as no nodes at all."""
    if not light.use_nodes or light.node_tree is None:
        return False
    nodes = light.node_tree.nodes
    if sorted(n.bl_idname for n in nodes) != ['ShaderNodeEmission', 'ShaderNodeOutputLight']:
        return True
    emission = next(n for n in nodes if n.bl_idname == 'ShaderNodeEmission')
    colour, strength = emission.inputs["Color"], emission.inputs["Strength"]
    return (colour.is_linked or strength.is_linked or abs(strength.default_value - 1.0) > 1e-6
            or any(abs(c - 1.0) > 1e-6 for c in tuple(colour.default_value)[:3]))


def _direct_light(light, matrix, version):
    """A point, spot or sun light in the solver's form (a dict), or None if unknown.

    Blender's lights shine along their local -z."""
    position = matrix[:3, 3]
    axis = -matrix[:3, 2]
    norm = np.linalg.norm(axis)
    axis = axis / norm if norm > 0 else np.array([0.0, 0.0, -1.0])
    colour = compat.light_colour(light)
    exposure, normalize = compat.light_exposure(light), compat.light_normalized(light)
    # 4.x: with soft falloff (the default) a light with a radius is a disk
    # facing the receiver, as in 3.x; without it, a sphere (light_units.py).
    soft = compat.light_soft_falloff(light)
    if light.type == 'POINT':
        units = light_units.point_light(version, light.energy, colour, light.shadow_soft_size, exposure, normalize,
                                        soft)
        return {"type": "point", "position": position, "intensity": units["intensity"],
                "radius": units["radius"], "shape": units["shape"].lower()}
    if light.type == 'SPOT':
        units = light_units.spot_light(version, light.energy, colour, light.shadow_soft_size,
                                       light.spot_size, light.spot_blend, exposure, normalize, soft)
        return {"type": "spot", "position": position, "intensity": units["intensity"],
                "radius": units["radius"], "shape": units["shape"].lower(),
                "direction": axis, "cos_half_angle": units["cos_half_angle"],
                "blend_width": units["cos_blend_width"], "cosine_falloff": units["cos_factor"]}
    if light.type == 'SUN':
        units = light_units.sun_light(version, light.energy, colour, light.angle, exposure, normalize)
        return {"type": "sun", "direction": axis, "irradiance": units["irradiance"], "angle": units["angle"]}
    return None


def world_radiance(world):
    """(radiance rgb or None, note) of a world: Background colour x strength when it is
    uniform (no texture feeding it), else None and a note for the warning."""
    if world is None:
        return None, ""
    if not world.use_nodes or world.node_tree is None:
        colour = np.array(world.color[:3], dtype=float)
        return (colour if np.any(colour > 0) else None), ""
    output = next((n for n in world.node_tree.nodes if n.type == 'OUTPUT_WORLD' and n.is_active_output), None)
    if output is None:
        output = next((n for n in world.node_tree.nodes if n.type == 'OUTPUT_WORLD'), None)
    if output is None or not output.inputs["Surface"].is_linked:
        return None, ""
    node = _linked_node(output.inputs["Surface"])
    if node is None:
        return None, ""
    if node.type == 'BACKGROUND' and not node.inputs["Color"].is_linked:
        strength = _scalar(node.inputs["Strength"], 1.0)
        if strength is not None:
            colour = np.array(node.inputs["Color"].default_value[:3], dtype=float) * strength
            return light_units.world_radiance(colour, 1.0) if np.any(colour > 0) else None, ""
    return None, "world %s (only a uniform Background colour is modelled)" % world.name


def _camera_visible(original, owner):
    """Cycles' camera ray visibility of an object, or of an instance (its own and its
    instancer's)."""
    return bool(original.visible_camera and owner.visible_camera)


def _unique(used, name):
    """`name`, or `name.2`, `name.3`... if taken already in this export."""
    count = used.get(name, 0) + 1
    used[name] = count
    return name if count == 1 else "%s.%d" % (name, count)


def face_object(exported):
    """face -> the name of the object input face `face` came from."""
    face_part, parts = exported.arrays["face_part"], exported.parts
    return lambda face: parts[face_part[face]].name
