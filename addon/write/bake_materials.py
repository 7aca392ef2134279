"""Lighting-only output: the refined result with the objects' own materials (Blender glue).

Every refined result mesh carries, beside the radiance attribute "Radiosity",
a point-domain FLOAT_COLOR attribute "Radiosity Light": the light gathered at
the vertex before the surface's reflectance and emission, H (radiance =
emission + reflectance x H, DESIGN.md section 3), and the original's UV maps
under their names (interpolated onto the result's corners, surface_uv.py).

Output "Lit Materials" ('LIGHTING') gives each result object copies of its
original's materials (the originals are never edited), each rewritten to emit
what the surface shows under the solved light: every diffuse BSDF becomes an
Emission shader of its colour source (Principled Base Color, Diffuse Color,
other BSDFs' Color: a constant or whatever node feeds it, image textures
included) times "Radiosity Light", plus the Principled BSDF's own emission
(colour x strength); Emission shaders and Mix/Add shaders stay as they are.
As in "Radiosity Emission", each polygon's back face is transparent: the two
sides of a two-sided face are two polygons facing away from each other. So a
textured scene renders with its textures, lit by the solution.
"""

import bpy
import numpy as np

from .. import compat
from ..model import surface_uv

LIGHT_ATTRIBUTE = "Radiosity Light"
# A lighting copy names its original material (custom property on the copy).
COPY_TAG = "radiosity_lighting_copy"
DEFAULT_MATERIAL = "Radiosity Light Default"
DEFAULT_COLOUR = (0.8, 0.8, 0.8)    # a face without material renders as grey 0.8 diffuse
SUFFIX = " Radiosity Light"


# --- Attributes and UV maps of a result mesh ----------------------------------------------

def add_light_attribute(mesh, irradiance):
    """Write the point-domain FLOAT_COLOR attribute "Radiosity Light" (H per vertex),
    leaving the active and render colour as they are."""
    colours = mesh.color_attributes
    old = colours.get(LIGHT_ATTRIBUTE)
    if old is not None:
        colours.remove(old)
    active = colours.active_color.name if colours.active_color is not None else None
    render = colours[colours.render_color_index].name if 0 <= colours.render_color_index < len(colours) else None
    attr = colours.new(LIGHT_ATTRIBUTE, 'FLOAT_COLOR', 'POINT')
    rgba = np.ones((len(irradiance), 4), dtype=np.float32)
    rgba[:, :3] = irradiance
    attr.data.foreach_set("color", rgba.ravel())
    names = [a.name for a in colours]
    if active is not None:
        colours.active_color = colours[active]
    if render is not None:
        colours.render_color_index = names.index(render)
    return attr


def add_uv_layers(mesh, part, corner_points, corner_faces):
    """The original's UV maps on a result mesh, under the same names, the render one
    marked so. corner_points (C, 3): the mesh's corners (unmoved result positions),
    corner_faces (C,): the part's input face of each."""
    if not part.uv_layers or part.triangles is None or len(corner_faces) != len(mesh.loops):
        return
    names = list(part.uv_layers)
    stacked = np.concatenate([part.uv_layers[n] for n in names], axis=1)
    values = surface_uv.interpolate(part.corner_points, part.face_sizes, part.triangles, part.triangle_face,
                                    stacked, corner_points, corner_faces)
    for i, name in enumerate(names):
        layer = mesh.uv_layers.new(name=name)
        compat.set_uv_layer(layer, values[:, 2 * i:2 * i + 2])
        if name == part.uv_render:
            layer.active_render = True
            mesh.uv_layers.active = layer


# --- Lighting copies of materials ---------------------------------------------------------

class LightingMaterials:
    """The lighting copies made by one bake, one per original material."""

    def __init__(self):
        self._copies = {}

    def assign(self, mesh, part, faces):
        """Give `mesh` the lighting copies of `part`'s material slots; `faces` (P,):
        the part's input face of each of the mesh's polygons."""
        slots = part.materials or [None]
        index = np.asarray(part.material_index, dtype=np.int64)[np.asarray(faces, dtype=np.int64)] \
            if part.material_index is not None else np.zeros(len(faces), dtype=np.int64)
        used = set(np.unique(index).tolist())
        for slot, material in enumerate(slots):
            mesh.materials.append(self.copy_of(material) if slot in used else None)
        mesh.polygons.foreach_set("material_index", index.astype(np.int32))

    def copy_of(self, material):
        key = material.name_full if material is not None else None
        if key not in self._copies:
            self._copies[key] = lighting_copy(material)
        return self._copies[key]

    def take_names(self):
        """Made while the last bake's copies still held the names: take them back."""
        for material in self._copies.values():
            compat.set_name(bpy.data.materials, material, material[COPY_TAG + "_name"])


def remove_unused():
    """Delete lighting copies no object uses any more (after the results are removed)."""
    for material in list(bpy.data.materials):
        if material.get(COPY_TAG) is not None and material.users == 0:
            bpy.data.materials.remove(material)


def lighting_copy(material):
    """A new material that shows `material` lit by "Radiosity Light" (None: the default surface)."""
    name = DEFAULT_MATERIAL if material is None else material.name + SUFFIX
    if material is None:
        copy = bpy.data.materials.new(name)
        copy[COPY_TAG] = ""
        _emission_only(copy, DEFAULT_COLOUR)
    else:
        copy = material.copy()
        compat.set_name(bpy.data.materials, copy, name)
        copy[COPY_TAG] = material.name_full
        copy.use_fake_user = False
        if not copy.use_nodes or copy.node_tree is None:
            # Cycles renders a material without nodes as diffuse of its viewport colour.
            _emission_only(copy, tuple(material.diffuse_color[:3]))
        else:
            _relight(copy.node_tree, tuple(material.diffuse_color[:3]))
    copy[COPY_TAG + "_name"] = name    # the name it takes once the last bake's copies are gone
    _backs_transparent(copy.node_tree)
    compat.set_cutout_transparency(copy)
    return copy


def _emission_only(material, colour):
    material.use_nodes = True
    nodes, links = material.node_tree.nodes, material.node_tree.links
    nodes.clear()
    output = nodes.new("ShaderNodeOutputMaterial")
    output.location = (400, 0)
    emission = nodes.new("ShaderNodeEmission")
    emission.location = (150, 0)
    product = _multiply_by_light(material.node_tree, _light_node(material.node_tree), None, colour)
    links.new(product, emission.inputs["Color"])
    links.new(emission.outputs[0], output.inputs["Surface"])


def _light_node(tree):
    for node in tree.nodes:
        if node.type == 'ATTRIBUTE' and node.get(COPY_TAG):
            return node
    node = tree.nodes.new("ShaderNodeAttribute")
    node.attribute_type = 'GEOMETRY'
    node.attribute_name = LIGHT_ATTRIBUTE
    node.label = LIGHT_ATTRIBUTE
    node[COPY_TAG] = True
    return node


def _source(socket):
    """(the output socket feeding `socket` or None, its constant rgb). A muted or
    invalid link passes the input's own value, as in a render."""
    if socket.is_linked:
        link = socket.links[0]
        if link.is_valid and not link.is_muted:
            return link.from_socket, None
    value = socket.default_value
    try:
        rgb = tuple(value[:3])
    except TypeError:           # a float input
        rgb = (float(value),) * 3
    return None, rgb


def _vector_math(tree, operation, location):
    node = tree.nodes.new("ShaderNodeVectorMath")
    node.operation = operation
    node.location = location
    return node


def _multiply_by_light(tree, light, source, constant, location=(0, 0)):
    """An output socket carrying (source or constant) x "Radiosity Light"."""
    node = _vector_math(tree, 'MULTIPLY', location)
    if source is not None:
        tree.links.new(source, node.inputs[0])
    else:
        node.inputs[0].default_value = constant
    tree.links.new(light.outputs["Color"], node.inputs[1])
    return node.outputs[0]


def _principled_emission(tree, node, location):
    """An output socket carrying a Principled BSDF's emission colour x strength, or None."""
    colour, colour_value = _source(compat.principled_emission(node))
    strength_socket = node.inputs.get("Emission Strength")
    strength, strength_value = (None, (1.0,)) if strength_socket is None else _source(strength_socket)
    if colour is None and max(colour_value) <= 0.0:
        return None
    if strength is None and strength_value[0] <= 0.0:
        return None
    scale = _vector_math(tree, 'SCALE', location)
    if colour is not None:
        tree.links.new(colour, scale.inputs[0])
    else:
        scale.inputs[0].default_value = colour_value
    scale_input = scale.inputs[3]      # "Scale"
    if strength is not None:
        tree.links.new(strength, scale_input)
    else:
        scale_input.default_value = strength_value[0]
    return scale.outputs[0]


# Shader nodes kept as they are: they emit, combine, or let light through.
_KEPT = {'EMISSION', 'MIX_SHADER', 'ADD_SHADER', 'BSDF_TRANSPARENT', 'HOLDOUT', 'BACKGROUND'}


def _relight(tree, viewport):
    """Replace every BSDF of `tree` by the Emission it shows under "Radiosity Light".
    A node group that outputs a shader (unknown inside, as to export.py) becomes
    the viewport colour `viewport` lit."""
    light = _light_node(tree)
    light.location = (-900, 400)
    for node in list(tree.nodes):
        group = node.type == 'GROUP' and any(o.type == 'SHADER' for o in node.outputs)
        if not (group or node.type.startswith('BSDF_') or node.type == 'SUBSURFACE_SCATTERING') \
                or node.type in _KEPT:
            continue
        x, y = node.location
        base = None
        if node.type == 'BSDF_PRINCIPLED':
            base = node.inputs["Base Color"]
        elif not group:
            base = node.inputs.get("Color")
        if group:
            colour = _multiply_by_light(tree, light, None, viewport, (x - 50, y - 300))
        elif base is not None:
            source, constant = _source(base)
            colour = _multiply_by_light(tree, light, source, constant, (x - 50, y - 300))
        else:
            colour = None
        if node.type == 'BSDF_PRINCIPLED':
            emitted = _principled_emission(tree, node, (x - 50, y - 450))
            if emitted is not None:
                total = _vector_math(tree, 'ADD', (x + 100, y - 350))
                tree.links.new(colour, total.inputs[0])
                tree.links.new(emitted, total.inputs[1])
                colour = total.outputs[0]
        emission = tree.nodes.new("ShaderNodeEmission")
        emission.location = (x + 250, y)
        emission.label = "%s, lit" % node.name
        emission.inputs["Strength"].default_value = 1.0
        if colour is not None:
            tree.links.new(colour, emission.inputs["Color"])
        else:
            emission.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
        for output in node.outputs:
            if output.type != 'SHADER':
                continue
            for link in list(output.links):
                tree.links.new(emission.outputs[0], link.to_socket)
        if not group:       # a group's other outputs may feed other nodes
            tree.nodes.remove(node)


def _backs_transparent(tree):
    """Every material output's surface shown on front faces only (transparent behind)."""
    for output in [n for n in tree.nodes if n.type == 'OUTPUT_MATERIAL']:
        surface = output.inputs["Surface"]
        if not surface.is_linked:
            continue
        shown = surface.links[0].from_socket
        x, y = output.location
        geometry = tree.nodes.new("ShaderNodeNewGeometry")
        geometry.location = (x - 200, y + 250)
        transparent = tree.nodes.new("ShaderNodeBsdfTransparent")
        transparent.location = (x - 200, y - 150)
        mix = tree.nodes.new("ShaderNodeMixShader")
        mix.location = (x, y)
        output.location = (x + 200, y)
        tree.links.new(geometry.outputs["Backfacing"], mix.inputs["Fac"])
        tree.links.new(shown, mix.inputs[1])
        tree.links.new(transparent.outputs["BSDF"], mix.inputs[2])
        tree.links.new(mix.outputs["Shader"], surface)
