"""Game-ready colours and the unlit material a solve bakes them with (Blender glue;
the colour math is model/display_colours.py; the glTF export of the result is
gltf_export.py).

With `scene.radiosity.display_colours` on, a solve bakes display-ready colours
(exposure, the scene's view transform, clamped to [0, 1]; display_colours.py
says why they are stored linear) and gives the result meshes the "Radiosity
Unlit" material instead of "Radiosity Emission". Blender's glTF exporter
(io_scene_gltf2, 3.4 to 5.0) writes that material as KHR_materials_unlit with
the colour attribute as COLOR_0. It recognises an unlit material by the shape
of its node tree (detect_shadeless_material), from the active Material Output
back: optionally a "mix-alpha" (Mix Shader with a Transparent BSDF in its first
shader input, the factor being alpha), then optionally the "light path trick"
(Mix Shader whose factor is Light Path's Is Camera Ray; its second shader input,
through an optional Emission node, is the colour), ending at a colour socket:

    [Light Path: Is Camera Ray] -> [Mix Fac]
    [Transparent BSDF] ----------> [Mix Shader 1] -> [Material Output Surface]
    [Color Attribute "Radiosity"] -> [Emission] -> [Mix Shader 2]

(the tree the glTF importer itself builds for an unlit material). The colour
is not a constant, so the base colour factor stays white and COLOR_0 alone
colours the surface. Which attribute becomes COLOR_0: 3.4 exports the render
colour attribute (export_colors); 4.2 and later follow the Color Attribute
node from the material (export_vertex_color 'MATERIAL'). Other rays than the
camera's see a Transparent BSDF, so in Cycles the result neither shadows nor
lights anything (its light is baked in).

Back faces: each side of a two-sided face is its own polygon, so the material
is one-sided by backface culling: EEVEE, the viewport and, through glTF's
doubleSided false, every engine skip back faces, and each side of a wall shows
its own light. It has no Backfacing -> transparent mix as "Radiosity Emission"
has: the 4.2+ exporters take the alpha mode from the mix-alpha's factor and
would write alphaMode BLEND (a clip, MASK) for it, which engines sort or
alpha-test; opaque is what a baked level wants. The cost: Cycles, which
ignores backface culling, shows the back of a one-sided face seen from behind
(a room's walls from outside) in its front's colour; render with the default
bake in Cycles.
"""

import os

import bpy

from ..model import display_colours
from . import bake

UNLIT_MATERIAL_NAME = "Radiosity Unlit"
UNLIT_TAG = "radiosity_unlit_material"


def unlit_material():
    """The shared material that shows the "Radiosity" attribute unlit, one-sided."""
    mat, made = bake.tagged_material(UNLIT_TAG, UNLIT_MATERIAL_NAME)
    if not made:
        return mat
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    colour = nodes.new("ShaderNodeVertexColor")
    colour.layer_name = bake.ATTRIBUTE
    colour.location = (-700, 0)
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Strength"].default_value = 1.0
    emission.location = (-450, 0)
    light_path = nodes.new("ShaderNodeLightPath")
    light_path.location = (-450, 450)
    hidden = nodes.new("ShaderNodeBsdfTransparent")
    hidden.location = (-450, 100)
    camera_mix = nodes.new("ShaderNodeMixShader")
    camera_mix.location = (-200, 100)
    output = nodes.new("ShaderNodeOutputMaterial")
    output.location = (50, 100)
    links.new(colour.outputs["Color"], emission.inputs["Color"])
    links.new(light_path.outputs["Is Camera Ray"], camera_mix.inputs["Fac"])
    links.new(hidden.outputs["BSDF"], camera_mix.inputs[1])
    links.new(emission.outputs["Emission"], camera_mix.inputs[2])
    links.new(camera_mix.outputs["Shader"], output.inputs["Surface"])
    mat.use_backface_culling = True
    if hasattr(mat, "blend_method"):
        # Opaque to EEVEE Legacy (its culling hides back faces) and to the glTF
        # exporter before 4.2, which takes alphaMode from it.
        mat.blend_method = 'OPAQUE'
    if hasattr(mat, "shadow_method"):
        mat.shadow_method = 'NONE'
    mat.diffuse_color = (1.0, 1.0, 1.0, 1.0)
    return mat


def is_game_ready(obj):
    """Whether a result object was baked with game-ready colours."""
    mesh = obj.data
    return (mesh is not None and len(mesh.materials) > 0
            and all(m is not None and m.get(UNLIT_TAG) for m in mesh.materials))


# --- The scene's view as display settings ------------------------------------------------

def ocio_config_path():
    """The OpenColorIO config Blender uses: $OCIO, else its own."""
    env = os.environ.get("OCIO")
    if env and os.path.isfile(env):
        return env
    for datafiles in (bpy.utils.system_resource('DATAFILES'),
                      os.path.join(bpy.utils.resource_path('LOCAL'), "datafiles")):
        path = os.path.join(datafiles or "", "colormanagement", "config.ocio")
        if datafiles and os.path.isfile(path):
            return path
    return ""


def import_ocio():
    """Whether PyOpenColorIO can be imported. Official Blender 4.x and 5.x ship it in
    their Python; bpy, Blender as a module of another Python, keeps it in its
    resources (python/lib/pythonX.Y/site-packages), looked in only for this import."""
    if display_colours.ocio_available():
        return True
    import sys
    bundled = os.path.join(bpy.utils.resource_path('LOCAL'), "python", "lib",
                           "python%d.%d" % sys.version_info[:2], "site-packages")
    if not os.path.isdir(os.path.join(bundled, "PyOpenColorIO")):
        return False
    sys.path.insert(0, bundled)
    try:
        return display_colours.ocio_available()
    finally:
        sys.path.remove(bundled)


def display_settings(scene):
    """(DisplaySettings, note) for the scene: the add-on's exposure plus the view's,
    the view transform, its look and gamma; the note says when the view needs
    OpenColorIO that this Blender's Python lacks (Standard is used then)."""
    view = scene.view_settings
    settings = display_colours.DisplaySettings(
        exposure=scene.radiosity.display_exposure + view.exposure,
        view=view.view_transform, gamma=view.gamma)
    if settings.view in (display_colours.STANDARD,) + display_colours.RAW_VIEWS:
        return settings, ""
    import_ocio()
    settings.transform = display_colours.ocio_display(
        ocio_config_path(), scene.display_settings.display_device, settings.view, view.look)
    if settings.transform is not None:
        return settings, ""
    why = ("this Blender's Python has no PyOpenColorIO" if not display_colours.ocio_available()
           else "OpenColorIO could not build it (look %r)" % view.look)
    return settings, ("game-ready colours use the Standard view transform instead of %r: %s"
                      % (settings.view, why))


def bake_options(scene):
    """(convert, material, note) for a game-ready bake: the function turning radiance
    into the colours written, the unlit material, and a warning or ""."""
    settings, note = display_settings(scene)
    return (lambda radiance: display_colours.game_colours(radiance, settings)), unlit_material(), note
