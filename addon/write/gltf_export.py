"""The glTF export of the result (Blender glue): `radiosity.export_gltf` writes
the result objects alone to a .glb or .gltf (selects them, calls the exporter
with the options its version has, restores the selection). Only a result baked
with game-ready colours and the unlit material (game_ready.py) is exported.
"""

import os

import bpy
from bpy.props import StringProperty
from bpy.types import Operator
from bpy_extras.io_utils import ExportHelper

from . import result_state
from .game_ready import is_game_ready

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
