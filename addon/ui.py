"""The Radiosity panel in Properties > Render.

Drawing only reads settings; it never changes data or calls operators.
"""

from bpy.types import Panel

from . import native


class RENDER_PT_radiosity(Panel):
    """Radiosity solver settings, the Solve button and the last solve's statistics"""

    bl_label = "Radiosity"
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"

    @classmethod
    def poll(cls, context):
        # Shown for every render engine: the result is plain colour attributes.
        return context.scene is not None

    def draw(self, context):
        settings = context.scene.radiosity
        layout = self.layout
        layout.use_property_split = True
        layout.use_property_decorate = False

        col = layout.column()
        col.prop(settings, "oracle")
        col.prop(settings, "quality", slider=True)

        col = layout.column(heading="Limits", align=True)
        col.prop(settings, "max_elements")
        col.prop(settings, "time_budget")
        col.prop(settings, "bounces")
        col.prop(settings, "min_element_size")

        col = layout.column()
        col.prop(settings, "visibility")
        sub = col.column()
        sub.active = settings.visibility == 'SAMPLED'
        sub.prop(settings, "rays")

        col = layout.column()
        col.prop(settings, "output")
        col.prop(settings, "show_wireframe")

        col = layout.column(heading="Game Export")
        col.active = settings.output != 'LIGHTING'  # it keeps the materials: nothing to make unlit
        col.prop(settings, "display_colours")
        sub = col.column()
        sub.active = settings.display_colours
        sub.prop(settings, "display_exposure")

        layout.separator()
        row = layout.row()
        row.scale_y = 1.5
        row.operator("radiosity.solve", icon='LIGHT_AREA')
        row = layout.row(align=True)
        row.operator("radiosity.toggle_result", icon='HIDE_OFF')
        row.operator("radiosity.clear", icon='X')
        layout.operator("radiosity.export_gltf", icon='EXPORT')
        if native.error() is not None:
            box = layout.box()
            box.alert = True
            box.label(text="Solver module failed to load; Solve reports why", icon='ERROR')

        draw_stats(layout, settings.stats)


def draw_stats(layout, stats):
    """Draw the last solve's statistics as labels: they are results, not settings."""
    box = layout.box()
    if not stats.valid:
        box.label(text="Not solved yet", icon='INFO')
        return
    col = box.column(align=True)
    col.label(text="Last solve: %s" % stats.status)
    col.label(text="Oracle: %s" % stats.oracle)
    col.label(text="Elements: {:,}   Links: {:,}".format(stats.elements, stats.links))
    col.label(text="Iterations: %d   Time: %.2f s" % (stats.iterations, stats.seconds))
    if stats.warning:
        col.label(text=stats.warning, icon='ERROR')
