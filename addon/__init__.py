"""Radiosity for Blender: hierarchical radiosity with perceptual refinement.

Solves the diffuse global illumination of a scene with hierarchical radiosity,
refined by a choice of oracles (standard BF, the perceptual oracle of Secchia
2000, gradient difference), and bakes the result into colour attributes that
show in the viewport and in renders. The lighting is computed by the native
module `_radiosity` next to this file; this package is the Blender glue, in
sub-packages that follow the data: read/ (the Blender scene into arrays),
model/ (no bpy: the arrays, units and words of what goes to and comes back
from the solver), solve/ (the module, the pipeline, reuse), write/ (the result
into meshes, attributes and materials; the glTF export) and ui/ (settings,
operators, panels).

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
    # Re-running register after F8 / "Reload Scripts": pick up edited modules,
    # each after those it imports.
    import importlib
    import sys

    for _name in ("compat", "model.solver_defaults", "model.oracles", "model.arrays", "model.light_units", "model.surface_uv", "model.display_colours",
                  "model.findings", "model.progress_text", "model.quality_meaning", "write.bake_materials",
                  "write.result_state", "read.render_visibility", "read.export", "write.bake",
                  "write.scene_transaction", "write.game_ready", "write.gltf_export", "solve.native",
                  "solve.solve_reuse", "solve.pipeline", "ui.properties", "ui.live_pacing", "ui.view_sync",
                  "ui.operators", "ui.panels"):
        if __name__ + "." + _name in sys.modules:
            importlib.reload(sys.modules[__name__ + "." + _name])

import bpy
from bpy.props import PointerProperty

from .solve import native, solve_reuse
from .ui import operators, panels, properties, view_sync
from .write import gltf_export

# Registration order matters: a PropertyGroup before the group that points to it.
classes = (
    properties.RadiosityStats,
    properties.RadiositySettings,
    operators.RADIOSITY_OT_solve,
    operators.RADIOSITY_OT_toggle_result,
    operators.RADIOSITY_OT_clear,
    gltf_export.RADIOSITY_OT_export_gltf,
    # The parent panel before its sub-panels, which show in this order.
    panels.RENDER_PT_radiosity,
    panels.RENDER_PT_radiosity_quality,
    panels.RENDER_PT_radiosity_output,
    panels.RENDER_PT_radiosity_stats,
    panels.VIEW3D_PT_radiosity,
    panels.VIEW3D_MT_radiosity,
)


def register():
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.radiosity = PointerProperty(
        type=properties.RadiositySettings,
        name="Radiosity",
        description="Radiosity solver settings",
    )
    panels.register()  # menu entries, the progress bar's property
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
    panels.unregister()
    del bpy.types.Scene.radiosity
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
