"""Writes a solution into the Blender scene (Blender glue; the array work is arrays.py).

- Refined output: one mesh object per exported part (object instance or area
  light) in the "Radiosity" collection, carrying the adaptive refinement, with
  a point-domain FLOAT_COLOR attribute "Radiosity" (radiance, as Cycles shows
  it with the Standard view transform) and the "Radiosity Emission" material,
  which emits that attribute with strength 1 and makes each polygon's back
  face transparent: the two sides of a two-sided face are two coincident
  polygons facing away from each other, and each is seen only from its side.
  A re-solve replaces them; the originals are never edited, only hidden in
  renders and viewport while the result is shown (reversibly: result_state.py).
- Lighting-only output (bake_materials.py): the refined objects with copies of
  their originals' materials, lit by the attribute "Radiosity Light" (H, the
  light before reflectance), which every refined mesh carries, with the
  originals' UV maps.
- Original output: a face-corner "Radiosity" attribute on the original meshes,
  sampled from the solution at their corners, without refinement.
"""

import bpy
import numpy as np

from . import arrays, bake_materials, compat, result_state, surface_uv
from .result_state import MATERIAL_TAG, ORIGINAL_ATTRIBUTE_TAG, RESULT_TAG

MATERIAL_NAME = "Radiosity Emission"
ATTRIBUTE = "Radiosity"
# Each side's polygons move this fraction of the scene's size towards the side
# they show (4 um in a 2 m room), so the two sides of a face never coincide;
# less than any gap contact.h models (a lamp 0.1 mm above a table top must
# stay in front of the table top under it).
SIDE_OFFSET = 2e-6


# --- The Radiosity Emission material -----------------------------------------------------

def emission_material():
    """The shared material that shows the "Radiosity" attribute as emitted radiance."""
    for mat in bpy.data.materials:
        if mat.get(MATERIAL_TAG):
            return mat
    mat = bpy.data.materials.new(MATERIAL_NAME)
    mat[MATERIAL_TAG] = True
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    attribute = nodes.new("ShaderNodeAttribute")
    attribute.attribute_type = 'GEOMETRY'
    attribute.attribute_name = ATTRIBUTE
    attribute.location = (-600, 100)
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    emission.location = (-300, 100)
    transparent = nodes.new("ShaderNodeBsdfTransparent")
    transparent.location = (-300, -100)
    backfacing = nodes.new("ShaderNodeNewGeometry")
    backfacing.location = (-600, 300)
    mix = nodes.new("ShaderNodeMixShader")
    mix.location = (0, 100)
    output = nodes.new("ShaderNodeOutputMaterial")
    output.location = (250, 100)
    links.new(attribute.outputs["Color"], emission.inputs["Color"])
    links.new(backfacing.outputs["Backfacing"], mix.inputs["Fac"])
    links.new(emission.outputs["Emission"], mix.inputs[1])
    links.new(transparent.outputs["BSDF"], mix.inputs[2])
    links.new(mix.outputs["Shader"], output.inputs["Surface"])
    # EEVEE: back faces culled and no shadows (the light is baked in).
    compat.set_cutout_transparency(mat)
    mat.diffuse_color = (1.0, 1.0, 1.0, 1.0)
    return mat


# --- Refined output ----------------------------------------------------------------------

def build_mesh(name, positions, face_vertices, face_sizes, radiance, light=None):
    """A new mesh from arrays, with the point-domain "Radiosity" colour attribute
    (and "Radiosity Light", H per vertex, if `light` is given)."""
    face_sizes = np.asarray(face_sizes, dtype=np.int32)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(len(positions))
    mesh.vertices.foreach_set("co", np.ascontiguousarray(positions, dtype=np.float32).ravel())
    mesh.loops.add(len(face_vertices))
    mesh.loops.foreach_set("vertex_index", np.ascontiguousarray(face_vertices, dtype=np.int32))
    mesh.polygons.add(len(face_sizes))
    starts = (np.cumsum(face_sizes) - face_sizes).astype(np.int32)
    compat.set_polygon_loops(mesh.polygons, starts, face_sizes)
    mesh.update(calc_edges=True)
    if light is not None:
        bake_materials.add_light_attribute(mesh, light)
    set_colour_attribute(mesh, radiance, 'POINT')
    return mesh


def set_colour_attribute(mesh, rgb, domain):
    """(Re)write the FLOAT_COLOR attribute "Radiosity" and make it active and rendered."""
    old = mesh.color_attributes.get(ATTRIBUTE)
    if old is not None:
        mesh.color_attributes.remove(old)
    attr = mesh.color_attributes.new(ATTRIBUTE, 'FLOAT_COLOR', domain)
    rgba = np.ones((len(rgb), 4), dtype=np.float32)
    rgba[:, :3] = rgb
    attr.data.foreach_set("color", rgba.ravel())
    mesh.color_attributes.active_color = attr
    names = [a.name for a in mesh.color_attributes]
    mesh.color_attributes.render_color_index = names.index(ATTRIBUTE)
    return attr


def write_refined(scene, exported, result, show_wireframe=False, convert=None, material=None,
                  lighting=False, replace_previous=None):
    """Replace the result objects by the solution's meshes. Returns the new objects.
    `convert` maps the (V, 3) radiance to the colours written and `material`
    replaces "Radiosity Emission" (game-ready colours: game_export.bake_options).
    `lighting`: with lighting copies of the originals' materials (bake_materials.py)
    instead (the copies of lights' parts keep `material`). `replace_previous(scene)` takes
    the previous result away (default result_state.remove_results; a SceneTransaction retires it)."""
    face_part = exported.arrays["face_part"]
    polygon_part = face_part[np.asarray(result.source_face, dtype=np.int64)]
    pieces = arrays.split_result(result.face_vertices, result.face_sizes, polygon_part,
                                 len(exported.parts))
    face_sizes = np.asarray(result.face_sizes)
    positions = unmoved = np.asarray(result.positions)
    if len(positions):
        extent = float(np.ptp(positions, axis=0).max())
        positions = arrays.offset_sides(positions, result.face_vertices, face_sizes,
                                        SIDE_OFFSET * extent)
    radiance = np.asarray(result.radiance)
    if convert is not None:
        radiance = convert(radiance)
    if material is None:
        material = emission_material()
    light = np.asarray(result.vertex_irradiance)
    source_face = np.asarray(result.source_face, dtype=np.int64)
    first_face = np.searchsorted(face_part, np.arange(len(exported.parts)))
    face_starts = np.cumsum(face_sizes) - face_sizes
    copies = bake_materials.LightingMaterials() if lighting else None
    new_objects = []
    try:
        for index, (part, piece) in enumerate(zip(exported.parts, pieces)):
            if piece is None:
                continue
            polygons, vertices, local = piece
            name = "%s Radiosity" % part.name
            mesh = build_mesh(name, positions[vertices], local, face_sizes[polygons], radiance[vertices],
                              light[vertices])
            corner_vertices, corner_faces = surface_uv.part_corner_queries(
                result.face_vertices, face_starts, face_sizes, polygons, source_face, first_face[index])
            bake_materials.add_uv_layers(mesh, part, unmoved[corner_vertices], corner_faces)
            if copies is not None and not part.is_light:
                copies.assign(mesh, part, source_face[polygons] - first_face[index])
            else:
                mesh.materials.append(material)
            obj = bpy.data.objects.new(name, mesh)
            obj[RESULT_TAG] = part.source
            obj["radiosity_name"] = name
            obj.show_wire = show_wireframe
            obj.show_all_edges = True
            new_objects.append(obj)
    except Exception:
        for obj in new_objects:
            mesh = obj.data
            bpy.data.objects.remove(obj)
            bpy.data.meshes.remove(mesh)
        bake_materials.remove_unused()
        raise
    (replace_previous or result_state.remove_results)(scene)
    coll = result_state.result_collection(scene)
    for obj in new_objects:
        coll.objects.link(obj)
        # Made while the old results still held the names: take them back (a user's
        # object or mesh of that name keeps it; the result takes name.001).
        compat.set_name(bpy.data.objects, obj, obj["radiosity_name"])
        compat.set_name(bpy.data.meshes, obj.data, obj["radiosity_name"])
    if copies is not None:
        copies.take_names()
    return new_objects


def set_wireframe(scene, show):
    for obj in result_state.result_objects(scene):
        obj.show_wire = show
        obj.show_all_edges = True


# --- Original output ---------------------------------------------------------------------

def write_original(scene, exported, result, convert=None):
    """Write a face-corner "Radiosity" attribute onto the original meshes (`convert`
    maps the (N, 3) radiance to the colours written, as in write_refined).

    Only for objects whose evaluated mesh has the original's topology (no
    generating modifiers), that are not instances, do not share their mesh and
    have no "Radiosity" attribute of the user's own. Returns (object name,
    reason) of those skipped.
    """
    positions = exported.arrays["positions"]
    extent = float(np.ptp(positions, axis=0).max()) if len(positions) else 1.0
    skipped = []
    starts = np.cumsum([p.face_count for p in exported.parts]) - [p.face_count for p in exported.parts]
    targets = []
    for part, start in zip(exported.parts, starts):
        if part.is_light or part.is_instance:
            continue
        obj = scene.objects.get(part.source)
        mesh = obj.data if obj is not None and obj.type == 'MESH' else None
        exported = np.arange(part.face_count) if part.polygons is None else part.polygons
        if (mesh is None or mesh.users > 1 or len(mesh.polygons) != (part.polygon_count or part.face_count)
                or not np.array_equal(_loop_total(mesh)[exported], part.face_sizes)):
            skipped.append((part.source, "instanced, shared or changed by modifiers"))
            continue
        if mesh.color_attributes.get(ATTRIBUTE) is not None and not mesh.get(ORIGINAL_ATTRIBUTE_TAG):
            skipped.append((part.source, "it has its own \"%s\" attribute" % ATTRIBUTE))
            continue
        targets.append((part, int(start), obj, mesh))
    if not targets:
        return skipped
    # One matching pass over every target's corners.
    points = np.concatenate([t[0].corner_points for t in targets])
    sizes = np.concatenate([t[0].face_sizes for t in targets])
    ids = np.concatenate([np.arange(t[1], t[1] + t[0].face_count) for t in targets])
    values, _ = arrays.corner_values(points, sizes, ids, result.positions, result.face_vertices,
                                     result.face_sizes, result.source_face, result.source_side,
                                     result.radiance, tolerance=1e-7 * max(extent, 1e-9))
    if convert is not None:
        values = convert(values)
    offset = 0
    for part, _, obj, mesh in targets:
        n = int(part.face_sizes.sum())
        part_values = values[offset:offset + n]
        offset += n
        loop_start = np.empty(len(mesh.polygons), dtype=np.int32)
        mesh.polygons.foreach_get("loop_start", loop_start)
        loop_total = _loop_total(mesh)
        if part.polygons is not None:   # faces left out of the solve stay black
            loop_start, loop_total = loop_start[part.polygons], loop_total[part.polygons]
        loops = arrays.polygon_corners(loop_start, loop_total, np.arange(len(mesh.loops)))
        if np.linalg.det(np.array(obj.matrix_world)[:3, :3]) < 0:
            loops = arrays.reverse_polygons(loops, loop_total)
        per_loop = np.zeros((len(mesh.loops), 3), dtype=np.float32)
        per_loop[loops] = part_values
        set_colour_attribute(mesh, per_loop, 'CORNER')
        mesh[ORIGINAL_ATTRIBUTE_TAG] = True
    return skipped


def _loop_total(mesh):
    total = np.empty(len(mesh.polygons), dtype=np.int32)
    mesh.polygons.foreach_get("loop_total", total)
    return total


def remove_original_attributes(scene):
    """Remove the attributes write_original wrote (never a user's own)."""
    for obj in scene.objects:
        if obj.type == 'MESH' and not obj.get(RESULT_TAG) and obj.data.get(ORIGINAL_ATTRIBUTE_TAG):
            attr = obj.data.color_attributes.get(ATTRIBUTE)
            if attr is not None:
                obj.data.color_attributes.remove(attr)
            del obj.data[ORIGINAL_ATTRIBUTE_TAG]
