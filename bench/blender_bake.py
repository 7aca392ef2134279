"""Cycles bake comparison (inside Blender): what a Blender user does instead of
radiosity. The scene, as the solver reads it, is rebuilt from the exported
arrays uniformly subdivided (bench/uniform_mesh.py) with Lambertian materials;
Cycles bakes its Combined pass (emitted + reflected radiance, all bounces) into
a point-domain float colour attribute; the baked colours are then rendered
through an Emission shader exactly like a radiosity solution.

    blender -b --factory-startup SCENE.blend --python bench/blender_bake.py -- \
        --addon BUILD/addon --jobs JOBS.json

JOBS.json: {"width", "height", "render_samples", "pairs": [[target vertices, bake samples], ...],
"out_dir", "results": OUT.json}. OUT.json lists per bake: vertices, polygons,
samples, bake_seconds (the bake operator alone) and the snapshot's EXR.
"""

import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import blender_common as common  # noqa: E402
import uniform_mesh  # noqa: E402

ATTRIBUTE = "Baked"


def material_for(rho, emission, cache):
    """A Diffuse BSDF of reflectance rho, or an Emission shader for an emitter."""
    key = tuple(np.round(np.r_[rho, emission], 6))
    if key in cache:
        return cache[key]
    mat = bpy.data.materials.new("Bake %d" % len(cache))
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    out = nodes.new("ShaderNodeOutputMaterial")
    if np.any(emission > 0):
        node = nodes.new("ShaderNodeEmission")
        node.inputs["Color"].default_value = (*emission, 1.0)
        node.inputs["Strength"].default_value = 1.0
        links.new(node.outputs["Emission"], out.inputs["Surface"])
    else:
        node = nodes.new("ShaderNodeBsdfDiffuse")
        node.inputs["Color"].default_value = (*rho, 1.0)
        links.new(node.outputs["BSDF"], out.inputs["Surface"])
    cache[key] = mat
    return mat


def shown_material():
    """The baked attribute through an Emission shader of strength 1 (both sides)."""
    mat = bpy.data.materials.new("Baked Emission")
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    attr = nodes.new("ShaderNodeAttribute")
    attr.attribute_type = 'GEOMETRY'
    attr.attribute_name = ATTRIBUTE
    emit = nodes.new("ShaderNodeEmission")
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(attr.outputs["Color"], emit.inputs["Color"])
    links.new(emit.outputs["Emission"], out.inputs["Surface"])
    return mat


def build_object(scene, arrays, h, cache):
    """One mesh object of the subdivided scene, one material slot per face material."""
    verts, polys, source = uniform_mesh.subdivide(arrays["positions"], arrays["face_vertices"],
                                                  arrays["face_sizes"], h)
    mesh = bpy.data.meshes.new("Subdivided")
    mesh.from_pydata(verts.tolist(), [], [p.tolist() for p in polys])
    slots = {}
    index = np.empty(len(polys), dtype=np.int32)
    for f in range(len(arrays["face_sizes"])):
        mat = material_for(arrays["reflectance"][f], arrays["emission"][f], cache)
        if mat.name not in slots:
            slots[mat.name] = len(mesh.materials)
            mesh.materials.append(mat)
    face_slot = np.array([slots[material_for(arrays["reflectance"][f], arrays["emission"][f], cache).name]
                          for f in range(len(arrays["face_sizes"]))])
    index[:] = face_slot[source]
    mesh.polygons.foreach_set("material_index", index)
    mesh.update()
    attr = mesh.color_attributes.new(ATTRIBUTE, 'FLOAT_COLOR', 'POINT')
    mesh.color_attributes.active_color = attr
    obj = bpy.data.objects.new("Subdivided", mesh)
    scene.collection.objects.link(obj)
    return obj


def bake(scene, obj, samples):
    scene.cycles.samples = samples
    scene.render.bake.target = 'VERTEX_COLORS'
    for o in bpy.context.view_layer.objects:
        o.select_set(o == obj)
    bpy.context.view_layer.objects.active = obj
    start = time.perf_counter()
    bpy.ops.object.bake(type='COMBINED')
    return time.perf_counter() - start


def main():
    jobs = common.start_jobs()
    from radiosity.read import export

    scene = bpy.context.scene
    arrays = export.export_scene(bpy.context).arrays
    # Only the rebuilt scene takes part from here on.
    for obj in list(scene.objects):
        if obj.type != 'CAMERA':
            obj.hide_render = True
    cache, shown, results = {}, shown_material(), []
    sizes = {}
    for target, samples in jobs["pairs"]:
        if target not in sizes:
            sizes[target] = uniform_mesh.cell_size_for(arrays["positions"], arrays["face_vertices"],
                                                       arrays["face_sizes"], target)
        h = sizes[target]
        obj = build_object(scene, arrays, h, cache)
        common.setup_render(scene, jobs["width"], jobs["height"], samples, path_traced=True)
        seconds = bake(scene, obj, samples)
        mesh = obj.data
        # Shown like a radiosity solution: the colours emitted, nothing else.
        mesh.materials.clear()
        mesh.materials.append(shown)
        mesh.polygons.foreach_set("material_index", np.zeros(len(mesh.polygons), dtype=np.int32))
        common.setup_render(scene, jobs["width"], jobs["height"], jobs["render_samples"])
        exr = os.path.join(jobs["out_dir"], "bake_v%d_s%d.exr" % (len(mesh.vertices), samples))
        common.render_to(scene, exr)
        results.append(dict(target_vertices=target, vertices=len(mesh.vertices), polygons=len(mesh.polygons),
                            samples=samples, bake_seconds=seconds, cell_size=h, exr=exr))
        common.say("baked %d vertices at %d samples in %.1f s" % (len(mesh.vertices), samples, seconds))
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)
    common.write_json(jobs["results"], results)


if __name__ == "__main__":
    main()
