"""What differs between the Blenders the add-on runs in (3.4 to 5.0), in one place.

Each difference is detected by feature (does the socket or property exist, is it
writable), so a Blender between or after the tested ones (3.4, 4.5, 5.0) takes the
path its API has. Only the area light's power-to-radiance factor goes by version,
since nothing in the API tells it (arrays.area_light_factor).
"""

import bpy
import numpy as np


def principled_emission(node):
    """The emission colour input of a Principled BSDF: "Emission" in 3.x,
    "Emission Color" since Principled v2 (4.0)."""
    socket = node.inputs.get("Emission Color")
    return socket if socket is not None else node.inputs["Emission"]


def set_polygon_loops(polygons, starts, sizes):
    """Give new polygons their loops. Blender 3.4 needs loop_total written; since
    3.6 it is read-only, derived from the next polygon's loop_start."""
    polygons.foreach_set("loop_start", starts)
    if not bpy.types.MeshPolygon.bl_rna.properties["loop_total"].is_readonly:
        polygons.foreach_set("loop_total", sizes)


def light_colour(light):
    """Linear RGB of a light: its colour, times its blackbody colour where it uses a
    temperature (4.5: use_temperature, temperature_color)."""
    colour = np.array(light.color[:3], dtype=float)
    if getattr(light, "use_temperature", False):
        colour *= np.array(light.temperature_color[:3], dtype=float)
    return colour


def light_exposure(light):
    """A light's exposure in stops (4.x lights; 0 before: power as given)."""
    return float(getattr(light, "exposure", 0.0))


def light_normalized(light):
    """Whether a light's power is spread over its area (always before 4.x, where
    lights have `normalize`)."""
    return bool(getattr(light, "normalize", True))


def light_soft_falloff(light):
    """Whether a point or spot light with a radius falls off softly (a disk facing
    the receiver in Cycles): 4.x's use_soft_falloff, default on; always before."""
    return bool(getattr(light, "use_soft_falloff", True))


def set_cutout_transparency(material):
    """EEVEE shows the baked material's transparent back faces as cut-outs, without
    shadows: blend_method 'CLIP' and shadow_method 'NONE' before EEVEE Next (4.2),
    surface_render_method 'DITHERED' since (its shadows follow the surface)."""
    material.use_backface_culling = True
    if hasattr(material, "surface_render_method"):
        material.surface_render_method = 'DITHERED'
    else:
        material.blend_method = 'CLIP'
        material.shadow_method = 'NONE'


def get_uv_layer(layer, loop_count):
    """A UV map's values per loop, (L, 2) float32: `layer.uv` (vectors, since 3.5)
    or `layer.data` (MeshUVLoop, 3.x)."""
    out = np.empty(2 * loop_count, dtype=np.float32)
    vectors = getattr(layer, "uv", None)
    if vectors is not None and len(vectors) == loop_count:
        vectors.foreach_get("vector", out)
    else:
        layer.data.foreach_get("uv", out)
    return out.reshape(-1, 2)


def set_uv_layer(layer, values):
    """Write a UV map's values per loop ((L, 2)), the inverse of get_uv_layer."""
    flat = np.ascontiguousarray(values, dtype=np.float32).ravel()
    vectors = getattr(layer, "uv", None)
    if vectors is not None and 2 * len(vectors) == len(flat):
        vectors.foreach_set("vector", flat)
    else:
        layer.data.foreach_set("uv", flat)


def set_name(collection, block, name):
    """Name `block` (an ID of bpy.data `collection`) `name`, or `name.001`, `name.002`...
    if another ID has it. Never asks Blender for a taken name: 3.4 then renames
    whichever of the two sorts first, which may be the user's object (measured;
    4.5 and 5.0 suffix the renamed one)."""
    if block.name == name:
        return
    # Names are at most 63 bytes (255 since 5.0); what Blender would cut could be taken.
    limit = bpy.types.ID.bl_rna.properties["name"].length_max - 1
    number = 0
    while True:
        suffix = ".%03d" % number if number else ""
        base = name.encode("utf-8")[:limit - len(suffix)].decode("utf-8", errors="ignore")
        candidate = base + suffix
        other = collection.get(candidate)
        if other is None or other == block:
            block.name = candidate
            return
        number += 1


def has_progress_bar(layout):
    """Whether the layout draws progress bars (UILayout.progress, Blender 4.0+); before,
    the panel draws one of its own (ui.draw_progress)."""
    return hasattr(layout, "progress")
