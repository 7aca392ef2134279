"""Radiosity for Blender: hierarchical radiosity with perceptual refinement.

Solves the diffuse global illumination of a scene with hierarchical radiosity,
refined by a choice of oracles (standard BF, the perceptual oracle of Secchia
2000, gradient difference), and bakes the result into colour attributes that
show in the viewport and in renders. The lighting is computed by the native
module `_radiosity` next to this file; this package is the Blender glue.

Scripting: `scene.radiosity` holds the settings, `bpy.ops.radiosity.solve()`
solves (also in `blender --background`).
"""

bl_info = {
    "name": "Radiosity",
    "author": "Radiosity for Blender contributors",
    "version": (0, 1, 0),
    "blender": (3, 4, 0),
    "location": "Properties > Render > Radiosity; Render menu; 3D View > View > Radiosity",
    "description": "Hierarchical radiosity with perceptual refinement, baked into colour attributes",
    # No project site yet: the README of the repository (placeholder address).
    "doc_url": "https://github.com/radiosity-for-blender/radiosity#radiosity-for-blender",
    "tracker_url": "https://github.com/radiosity-for-blender/radiosity/issues",
    "category": "Render",
}

if "bpy" in locals():
    # Re-running register after F8 / "Reload Scripts": pick up edited modules.
    import importlib

    for _name in ("native", "compat", "arrays", "light_units", "surface_uv", "bake_materials", "result_state",
                  "export", "bake", "scene_transaction", "display_colours", "game_export", "properties",
                  "progress_text", "live_pacing", "solve_reuse", "pipeline", "operators", "ui"):
        if _name in locals():
            importlib.reload(locals()[_name])

import bpy
from bpy.props import PointerProperty

from . import game_export, native, operators, properties, solve_reuse, ui, view_sync

# Registration order matters: a PropertyGroup before the group that points to it.
classes = (
    properties.RadiosityStats,
    properties.RadiositySettings,
    operators.RADIOSITY_OT_solve,
    operators.RADIOSITY_OT_toggle_result,
    operators.RADIOSITY_OT_clear,
    game_export.RADIOSITY_OT_export_gltf,
    # The parent panel before its sub-panels, which show in this order.
    ui.RENDER_PT_radiosity,
    ui.RENDER_PT_radiosity_quality,
    ui.RENDER_PT_radiosity_output,
    ui.RENDER_PT_radiosity_stats,
    ui.VIEW3D_PT_radiosity,
    ui.VIEW3D_MT_radiosity,
)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.radiosity = PointerProperty(
        type=properties.RadiositySettings,
        name="Radiosity",
        description="Radiosity solver settings",
    )
    ui.register()  # menu entries, the progress bar's property
    solve_reuse.register()
    view_sync.register()
    operators.register()  # an undo during a solve stops it
    # Try the native module now so the panel can say at once if it is unusable;
    # registration itself never depends on it.
    try:
        native.load()
    except native.NativeUnavailable as err:
        print("Radiosity:", err)


def unregister():
    operators.unregister()
    view_sync.unregister()
    solve_reuse.unregister()
    ui.unregister()
    del bpy.types.Scene.radiosity
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
