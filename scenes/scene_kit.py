"""Shared pieces of the scene builders: geometry as numpy arrays (no Blender
needed), and the functions that make objects, materials, a camera and render
settings from it inside Blender (each imports bpy when called).

Geometry is built from numpy arrays of quads with outward (for objects) or
inward (for rooms) normals, so every face's front side is the side that sees
the rest of the scene. Materials are plain: Principled BSDF with a base colour
and no specular layer (a diffuse surface, the scenes radiosity models), or a
Diffuse BSDF where a scene is built Lambertian from the start (the Cornell box,
the contact scenes), and an Emission shader for lights. Render settings make a Cycles render of the scene a
reference for the radiosity solution: CPU, Standard view transform, enough
diffuse bounces, no clamping.
"""

import numpy as np

# Which corner of a box each of its 8 corners is, index = x + 2 y + 4 z: 0 at
# the low corner's coordinate, 1 at the high one's.
_BOX_CORNERS = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=bool)
# Its faces, counter-clockwise seen from outside.
BOX_FACES = {
    "bottom": (0, 2, 3, 1),
    "top": (4, 5, 7, 6),
    "front": (0, 1, 5, 4),   # -y
    "back": (2, 6, 7, 3),    # +y
    "left": (0, 4, 6, 2),    # -x
    "right": (1, 3, 7, 5),   # +x
}


def empty_file():
    """Start from an empty file (no factory cube, light or camera)."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    return bpy.context.scene


def box(size, omit=()):
    """(vertices, quads) of an axis-aligned box centred on the origin, normals out (box_between)."""
    half = 0.5 * np.asarray(size, dtype=float)
    return box_between(-half, half, omit)


def box_between(lo, hi, omit=(), inward=False):
    """(vertices (8, 3), quads (k, 4)) of the axis-aligned box from corner `lo` to
    `hi`: its faces in BOX_FACES' order, normals out, or in (`inward`: a room
    seen from inside; each quad's corners reversed).

    `omit` names faces that touch other surfaces (a leg's top under a table);
    leaving them out keeps coincident, invisible faces out of the solve.
    """
    verts = np.where(_BOX_CORNERS, np.asarray(hi, dtype=float), np.asarray(lo, dtype=float))
    quads = np.array([f for name, f in BOX_FACES.items() if name not in omit]).reshape(-1, 4)
    return verts, quads[:, ::-1] if inward else quads


def quad(origin, u, v):
    """(vertices, quads) of the parallelogram origin + [0,1] u + [0,1] v; normal u x v."""
    o, u, v = (np.asarray(a, dtype=float) for a in (origin, u, v))
    return np.array([o, o + u, o + u + v, o + v]), np.array([[0, 1, 2, 3]])


def room_walls(lo, hi, opening=None):
    """The six inner faces of the room between corners lo and hi, normals inward.

    Returns {name: (vertices, quads)} for floor, ceiling and the walls
    left (-x), right (+x), front (-y), back (+y). `opening` = ((x0, y0), (x1, y1))
    leaves a hole in the ceiling for a recessed light (ceiling_with_opening).
    """
    (x0, y0, z0), (x1, y1, z1) = lo, hi
    dx, dy, dz = x1 - x0, y1 - y0, z1 - z0
    return {
        "Floor": quad((x0, y0, z0), (dx, 0, 0), (0, dy, 0)),
        "Ceiling": quad((x0, y0, z1), (0, dy, 0), (dx, 0, 0)),
        "Wall.Left": quad((x0, y0, z0), (0, dy, 0), (0, 0, dz)),
        "Wall.Right": quad((x1, y0, z0), (0, 0, dz), (0, dy, 0)),
        "Wall.Front": quad((x0, y0, z0), (0, 0, dz), (dx, 0, 0)),
        "Wall.Back": quad((x0, y1, z0), (dx, 0, 0), (0, 0, dz)),
    } | ({"Ceiling": ceiling_with_opening(lo, hi, *opening)} if opening else {})


def light_opening(center, size_x, size_y):
    """((x0, y0), (x1, y1)) of a light of size_x by size_y centred at `center` (x, y)."""
    cx, cy = center[:2]
    return (cx - size_x / 2, cy - size_y / 2), (cx + size_x / 2, cy + size_y / 2)


def ceiling_with_opening(lo, hi, opening_lo, opening_hi):
    """(vertices, quads) of a ceiling at z = hi[2] facing down, with a rectangular
    opening between (x, y) corners opening_lo and opening_hi for a recessed light.

    Four quads around the opening: the light sits in it, flush with the
    ceiling, so no ceiling lies just above the light (a surface a centimetre
    above an emitter's back is a hot spot that is hard to solve and unlike a
    real recessed panel).
    """
    (x0, y0, _), (x1, y1, z) = lo, hi
    (a0, b0), (a1, b1) = opening_lo, opening_hi
    pieces = [
        ((x0, y0), (x1, b0)),   # in front of the opening, full width
        ((x0, b1), (x1, y1)),   # behind it, full width
        ((x0, b0), (a0, b1)),   # left of it
        ((a1, b0), (x1, b1)),   # right of it
    ]
    verts, quads = [], []
    for (u0, v0), (u1, v1) in pieces:
        n = len(verts)
        # Counter-clockwise seen from below: normal -z.
        verts += [(u0, v0, z), (u0, v1, z), (u1, v1, z), (u1, v0, z)]
        quads.append((n, n + 1, n + 2, n + 3))
    return np.array(verts, dtype=float), np.array(quads)


def ceiling_light(center, size_x, size_y):
    """(vertices, quads) of a rectangle facing down (-z) centred at `center`."""
    cx, cy, cz = center
    return quad((cx - size_x / 2, cy - size_y / 2, cz), (0, size_y, 0), (size_x, 0, 0))


def add_mesh(scene, name, geometry, material, location=(0, 0, 0), rotation=(0, 0, 0)):
    """Link a new object made of `geometry` = (vertices, faces: an array of quads
    or a list of vertex index lists) to the scene."""
    import bpy

    verts, faces = geometry
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(verts.tolist(), [], faces.tolist() if hasattr(faces, "tolist") else faces)
    mesh.validate()
    mesh.materials.append(material)
    obj = bpy.data.objects.new(name, mesh)
    obj.location = location
    obj.rotation_euler = rotation
    scene.collection.objects.link(obj)
    return obj


# Principled BSDF inputs that Principled v2 (Blender 4.0) renamed: 3.x name -> 4.x name.
# Both "Specular" and "Specular IOR Level" at 0 mean no specular layer.
PRINCIPLED_V2_NAMES = {"Specular": "Specular IOR Level", "Emission": "Emission Color",
                       "Transmission": "Transmission Weight"}


def principled_input(node, name):
    """Input `name` (its 3.x name) of a Principled BSDF node, in any Blender."""
    renamed = PRINCIPLED_V2_NAMES.get(name)
    if renamed is not None and renamed in node.inputs:
        return node.inputs[renamed]
    return node.inputs[name]


def diffuse_material(name, color):
    """A diffuse material: Principled BSDF with `color` (linear RGB) and no specular."""
    import bpy

    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    principled_input(bsdf, "Specular").default_value = 0.0
    mat.diffuse_color = (*color, 1.0)  # the viewport colour in Solid shading
    return mat


def lambertian_material(name, color):
    """A Lambertian material: a Diffuse BSDF of `color` (linear RGB), the surface
    radiosity models exactly (the Principled BSDF's diffuse is not Lambertian).
    The Diffuse BSDF node and its Color input are the same in Blender 3.x to 5.x."""
    import bpy

    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    bsdf = nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*color, 1.0)
    output = nodes.new("ShaderNodeOutputMaterial")
    output.location = (300, 0)
    links.new(bsdf.outputs["BSDF"], output.inputs["Surface"])
    mat.diffuse_color = (*color, 1.0)
    return mat


def emission_material(name, strength, color=(1.0, 1.0, 1.0)):
    """A light: an Emission shader of radiance color x strength, nothing else."""
    import bpy

    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*color, 1.0)
    emission.inputs["Strength"].default_value = strength
    output = nodes.new("ShaderNodeOutputMaterial")
    output.location = (300, 0)
    links.new(emission.outputs["Emission"], output.inputs["Surface"])
    mat.diffuse_color = (*color, 1.0)
    return mat


def add_camera(scene, location, target, lens=20.0):
    """A camera at `location` looking at `target`, set as the scene camera."""
    import bpy
    from mathutils import Vector

    data = bpy.data.cameras.new("Camera")
    data.lens = lens
    data.clip_start = 0.01
    cam = bpy.data.objects.new("Camera", data)
    cam.location = location
    direction = Vector(target) - Vector(location)
    cam.rotation_euler = direction.to_track_quat('-Z', 'Y').to_euler()
    scene.collection.objects.link(cam)
    scene.camera = cam
    return cam


def cycles_denoiser_available():
    """Whether this Blender's Cycles can denoise on the CPU (OpenImageDenoise)."""
    try:
        import _cycles
    except ImportError:
        return False
    return bool(getattr(_cycles, "with_openimagedenoise", False))


def setup_render(scene, resolution=(640, 480), samples=128):
    """Cycles on the CPU, Standard view transform, a black world."""
    import bpy

    scene.render.engine = 'CYCLES'
    scene.cycles.device = 'CPU'
    scene.cycles.samples = samples
    # Enough bounces for a closed room to converge, and no clamping: a Cycles
    # render of the scene is a reference for the radiosity solution.
    scene.cycles.max_bounces = 32
    scene.cycles.diffuse_bounces = 32
    scene.cycles.sample_clamp_indirect = 0.0
    # Denoising (on by default) where this Blender's Cycles has a denoiser:
    # Debian's 3.4 is built without OpenImageDenoise, and F12 with Denoise on
    # gave an empty image there.
    scene.cycles.use_denoising = cycles_denoiser_available()
    scene.render.resolution_x, scene.render.resolution_y = resolution
    scene.render.resolution_percentage = 100
    scene.view_settings.view_transform = 'Standard'
    scene.view_settings.look = 'None'
    scene.view_settings.exposure = 0.0
    scene.view_settings.gamma = 1.0

    world = bpy.data.worlds.new("World")
    world.color = (0.0, 0.0, 0.0)
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
    scene.world = world


def make_lambertian(material):
    """Replace a Principled BSDF by a Diffuse BSDF of its base colour: Cycles'
    Principled diffuse is not Lambertian, the radiosity model is, so comparisons
    with Cycles use this. Emission-only materials stay as they are."""
    if not material.use_nodes:
        return
    nodes, links = material.node_tree.nodes, material.node_tree.links
    bsdf = next((n for n in nodes if n.type == 'BSDF_PRINCIPLED'), None)
    if bsdf is None:
        return
    output = next(n for n in nodes if n.type == 'OUTPUT_MATERIAL')
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = bsdf.inputs["Base Color"].default_value
    nodes.remove(bsdf)
    links.new(diffuse.outputs["BSDF"], output.inputs["Surface"])
