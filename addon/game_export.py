"""Game-ready output (Blender glue; the colour math is display_colours.py).

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

`radiosity.export_gltf` writes the result objects alone to a .glb or .gltf
(selects them, calls the exporter with the options its version has, restores
the selection).
"""

import os

import bpy
from bpy.props import StringProperty
from bpy.types import Operator
from bpy_extras.io_utils import ExportHelper

from . import bake, display_colours, result_state

UNLIT_MATERIAL_NAME = "Radiosity Unlit"
UNLIT_TAG = "radiosity_unlit_material"


def unlit_material():
    """The shared material that shows the "Radiosity" attribute unlit, one-sided."""
    for mat in bpy.data.materials:
        if mat.get(UNLIT_TAG):
            return mat
    mat = bpy.data.materials.new(UNLIT_MATERIAL_NAME)
    mat[UNLIT_TAG] = True
    mat.use_nodes = True
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    nodes.clear()
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


# --- Export of the result only -----------------------------------------------------------

def gltf_options(operator_properties, filepath):
    """Keyword arguments for bpy.ops.export_scene.gltf that export the selected result
    objects with their colour attribute as COLOR_0, chosen by which properties the
    installed exporter has (3.4: export_colors; 4.x: export_vertex_color and friends)."""
    props = set(operator_properties)
    glb = not filepath.lower().endswith(".gltf")
    wanted = {
        "filepath": filepath,
        "export_format": 'GLB' if glb else 'GLTF_SEPARATE',
        "use_selection": True,
        "use_visible": False,
        "use_renderable": False,
        "use_active_collection": False,
        "export_materials": 'EXPORT',
        "export_apply": False,
        "export_yup": True,
        "export_cameras": False,
        "export_lights": False,
        "export_animations": False,
        "export_extras": False,
        # The colour attribute as COLOR_0, not also as a custom _RADIOSITY attribute.
        "export_attributes": False,
        "export_colors": True,                      # 3.x
        "export_vertex_color": 'MATERIAL',          # 4.2+: the attribute the material names
        "export_all_vertex_colors": False,
        "export_active_vertex_color_when_no_material": True,
    }
    return {k: v for k, v in wanted.items() if k in props}


def gltf_exporter_properties():
    """Names of bpy.ops.export_scene.gltf's properties, enabling io_scene_gltf2 if needed;
    None when there is no glTF exporter."""
    for attempt in range(2):
        try:
            return [p.identifier for p in bpy.ops.export_scene.gltf.get_rna_type().properties]
        except (KeyError, AttributeError):
            if attempt:
                return None
            import addon_utils
            addon_utils.enable("io_scene_gltf2", default_set=True)
    return None


def exported_objects(context):
    """The result objects of the context's scene in its view layer."""
    view_layer = context.view_layer
    return [o for o in result_state.result_objects(context.scene) if view_layer.objects.get(o.name) is not None]


def why_not_exportable(context):
    """Why the context's result cannot be exported, for the user; "" when it can."""
    objects = exported_objects(context)
    if not objects:
        return "No radiosity result to export: solve with output New Meshes first"
    not_ready = [o.name for o in objects if not is_game_ready(o)]
    if not_ready:
        return ("The result holds HDR radiance, not display colours: tick Game-Ready Colours "
                "(Radiosity > Output: Colours For Games) and solve again before exporting (%s)"
                % ", ".join(not_ready[:3]))
    return ""


def export_gltf(context, filepath):
    """Write the result objects of the context's scene to `filepath` (.glb or .gltf;
    .glb added to another name). Returns (the objects written, the path); raises
    RuntimeError with a message for the user."""
    scene, view_layer = context.scene, context.view_layer
    if os.path.splitext(filepath)[1].lower() not in (".glb", ".gltf"):
        filepath += ".glb"
    problem = why_not_exportable(context)
    if problem:
        raise RuntimeError(problem)
    objects = exported_objects(context)
    props = gltf_exporter_properties()
    if props is None:
        raise RuntimeError("The glTF exporter (io_scene_gltf2) is not available in this Blender")
    selected = [o for o in view_layer.objects if o.select_get(view_layer=view_layer)]
    active = view_layer.objects.active
    hidden = {}
    try:
        for obj in selected:
            obj.select_set(False, view_layer=view_layer)
        for obj in objects:
            # Results hidden by Toggle are still the ones to export, and results are
            # not selectable (bake.write_refined) until made so for the exporter.
            hidden[obj.name] = (obj.hide_viewport, obj.hide_get(view_layer=view_layer), obj.hide_select)
            obj.hide_viewport = False
            obj.hide_set(False, view_layer=view_layer)
            obj.hide_select = False
            obj.select_set(True, view_layer=view_layer)
        view_layer.objects.active = objects[0]
        options = gltf_options(props, filepath)
        result = bpy.ops.export_scene.gltf(**options)
        if 'FINISHED' not in result:
            raise RuntimeError("The glTF exporter did not finish: %s" % ", ".join(sorted(result)))
    finally:
        for obj in objects:
            obj.select_set(False, view_layer=view_layer)
            if obj.name in hidden:
                obj.hide_viewport = hidden[obj.name][0]
                obj.hide_set(hidden[obj.name][1], view_layer=view_layer)
                obj.hide_select = hidden[obj.name][2]
        for obj in selected:
            if view_layer.objects.get(obj.name) is not None:
                obj.select_set(True, view_layer=view_layer)
        view_layer.objects.active = active
    return objects, filepath


class RADIOSITY_OT_export_gltf(Operator, ExportHelper):
    """Export the radiosity result objects alone (not the hidden originals) to glTF, with
    their game-ready colours as COLOR_0 and an unlit material"""

    bl_idname = "radiosity.export_gltf"
    bl_label = "Export Radiosity glTF"
    bl_options = {'REGISTER'}

    filename_ext = ".glb"
    filter_glob: StringProperty(default="*.glb;*.gltf", options={'HIDDEN'})
    check_extension = False  # .glb by default, .gltf allowed

    @classmethod
    def poll(cls, context):
        if context.scene is None:
            return False
        if not result_state.result_objects(context.scene):
            cls.poll_message_set("No radiosity result to export")
            return False
        return True

    def invoke(self, context, event):
        # Refused before the file browser opens, not after the user chose a file.
        problem = why_not_exportable(context)
        if problem:
            self.report({'ERROR'}, problem)
            return {'CANCELLED'}
        return ExportHelper.invoke(self, context, event)

    def execute(self, context):
        try:
            objects, path = export_gltf(context, self.filepath)
        except RuntimeError as err:
            self.report({'ERROR'}, str(err))
            return {'CANCELLED'}
        self.report({'INFO'}, "Radiosity: %d objects exported to %s" % (len(objects), path))
        return {'FINISHED'}
