"""The Radiosity panels in Properties > Render and in the 3D view's sidebar, and
the add-on's menu entries.

The parent panel holds the Solve button (with a progress bar while a solve
runs) and Toggle / Remove; its sub-panels hold the settings (Quality and
Limits, Output) and the last solve's Statistics. Solve, Toggle and Remove are
also in the Render menu and in the 3D view's View > Radiosity menu, which is
where F3 search finds them; the glTF export of the result is in File > Export. The sidebar's Radiosity tab (N) holds Solve, the
oracle and quality, Toggle and Remove.

Drawing only reads settings and the running solve's progress; it never changes
data or calls operators. It is cheap: the operator redraws the panel while a
solve runs. Labels are short enough for the default Properties width
(tests/blender/test_addon.py measures them); longer text (errors, warnings,
statuses) is wrapped to the region's width.
"""

import textwrap

import bpy
from bpy.props import FloatProperty
from bpy.types import Menu, Panel

from .. import compat
from ..model.progress_text import progress_fraction, progress_texts
from ..model.quality_meaning import quality_text
from ..solve import native, pipeline, solve_reuse
from ..write import result_state
from . import operators

EDIT_WARNING = "Edits to radiosity results are replaced by the next Solve"
SOLVING_LOCK = "The window works meanwhile; Undo, Delete and mode switches wait for the end"
# Width of a character of the UI font at scale 1, above the widest lines of the texts
# drawn here (5.4 px in 3.x's DejaVu Sans; 4.x's Inter is a little wider), what a
# panel's layout is narrower than its region, and the room around a label's text,
# an icon and a box's margins take: wrapped lines fit, cut at words.
CHAR_WIDTH = 6.0
PANEL_MARGIN = 33
LABEL_PAD = 5
ICON_WIDTH = 20
BOX_PAD = 10
# A slider's value beside its text (the progress bar before 4.0).
SLIDER_VALUE = 40


def region_width(context):
    """The drawing region's width in pixels at UI scale 1, or None outside a region."""
    region = getattr(context, "region", None)
    if region is None:
        return None
    scale = context.preferences.system.ui_scale or 1.0  # 0 without a window (3.4)
    return region.width / scale


def wrap(text, context, indent=0):
    """`text` in lines that fit the region less `indent` pixels (one line when the
    width is unknown)."""
    width = region_width(context)
    if width is None:
        return [text]
    chars = max(16, int((width - PANEL_MARGIN - LABEL_PAD - indent) / CHAR_WIDTH))
    return textwrap.wrap(text, chars) or [text]


def draw_wrapped(layout, context, text, icon='NONE', indent=0):
    """Labels of `text` wrapped to the region, the icon on the first line; `indent`:
    what the layout is narrower than the panel (BOX_PAD in a box)."""
    col = layout.column(align=True)
    if icon != 'NONE':
        indent += ICON_WIDTH
    for index, line in enumerate(wrap(text, context, indent)):
        col.label(text=line, icon=icon if index == 0 or icon == 'NONE' else 'BLANK1')
    return col


def fits(text, context, indent=0):
    return len(wrap(text, context, indent)) == 1


# --- Progress ---------------------------------------------------------------------------

def _progress_percent(wm):
    # The fallback bar's value: read from the running solve, never stored.
    return 100.0 * progress_fraction(operators.running_progress())


def _ignore(wm, value):
    pass  # a bar, not a setting: dragging it changes nothing


# Where UILayout has no progress bar (before 4.0) a slider of this property is one:
# a fill to the fraction with the text over it. A setter that ignores the value keeps
# it drawn live rather than greyed out as a read-only property would be.
PROGRESS_PROPERTY = FloatProperty(
    name="Progress",
    description="How far the running radiosity solve is",
    subtype='PERCENTAGE',
    min=0.0,
    max=100.0,
    precision=0,
    get=_progress_percent,
    set=_ignore,
)


def draw_progress(layout, context, progress):
    """The running solve's progress bar and counts, with how to stop it."""
    full, short, count = progress_texts(progress)
    col = layout.column(align=True)
    bar = col.column(align=True)
    native_bar = compat.has_progress_bar(bar)
    text = full if fits(full, context, indent=0 if native_bar else SLIDER_VALUE) else short
    if native_bar:
        bar.progress(factor=progress_fraction(progress), type='BAR', text=text)
    else:
        bar.prop(context.window_manager, "radiosity_progress", slider=True, text=text)
    if text == short and count:
        col.label(text=count)  # below the bar where the bar has no room for it
    col.label(text="Esc to cancel", icon='CANCEL')
    # The solve's modal handler passes every event on but the keys of what must
    # wait (operators.LOCKED_OPERATORS): say so.
    draw_wrapped(col, context, SOLVING_LOCK, icon='LOCKED')


# --- Panels -----------------------------------------------------------------------------

class RadiosityPanel:
    bl_space_type = 'PROPERTIES'
    bl_region_type = 'WINDOW'
    bl_context = "render"


def split_layout(layout):
    """`layout` with labels beside the values and no keyframe dots, as
    Blender's own render settings are laid out."""
    layout.use_property_split = True
    layout.use_property_decorate = False
    return layout


def result_selected(context):
    """Whether the user selected a generated result object (possible through the
    Outliner, or after making it selectable)."""
    objects = context.view_layer.objects
    active = objects.active
    if active is not None and active.get(result_state.RESULT_TAG):
        return True
    return any(o.get(result_state.RESULT_TAG) for o in objects.selected)


def toggle_icon(scene):
    """Toggle's eye: open while the result is shown, closed while the originals are."""
    return 'HIDE_OFF' if result_state.result_shown(scene) else 'HIDE_ON'


def draw_solve(layout, context):
    """Solve with the running solve's progress, Toggle and Remove, and what
    stops the add-on from working or warns about edits."""
    col = layout.column()
    row = col.row()
    row.scale_y = 1.5
    row.operator("radiosity.solve", icon='LIGHT_AREA')
    progress = operators.running_progress()
    if progress is not None:
        draw_progress(col, context, progress)
    # Side by side where they fit, else one above the other.
    flow = layout.grid_flow(row_major=True, columns=0, even_columns=True, align=True)
    flow.operator("radiosity.toggle_result", text="Toggle Result", icon=toggle_icon(context.scene))
    flow.operator("radiosity.clear", text="Remove Result", icon='X')
    advice = native.advice()
    if advice is not None:
        box = layout.box()
        box.alert = True
        box.label(text="Solver failed to load", icon='ERROR')
        draw_wrapped(box, context, advice, indent=BOX_PAD)
    if result_selected(context):
        box = layout.box()
        draw_wrapped(box, context, EDIT_WARNING, icon='ERROR', indent=BOX_PAD)


def draw_oracle_and_quality(layout, context, settings):
    """The oracle, the Quality slider and what it means for that oracle: a
    headline and, greyed under it, what its number is."""
    col = layout.column()
    col.prop(settings, "oracle")
    col.prop(settings, "quality", slider=True)
    meaning, detail = quality_text(settings, native.loaded())
    if meaning:
        row = col.row()
        row.alignment = 'RIGHT'
        row.label(text=meaning)
    if detail:
        draw_wrapped(col, context, detail).active = False
    return col


class RENDER_PT_radiosity(RadiosityPanel, Panel):
    """Solve, the progress of a running solve, and the result's Toggle and Remove"""

    bl_label = "Radiosity"

    @classmethod
    def poll(cls, context):
        # Shown for every render engine: the result is plain colour attributes.
        return context.scene is not None

    def draw(self, context):
        draw_solve(self.layout, context)


class VIEW3D_PT_radiosity(Panel):
    """Solve, the result's Toggle and Remove, the oracle and quality, in the
    3D view's sidebar (N), where tools like this are looked for; the rest of
    the settings stay in Properties > Render"""

    bl_label = "Radiosity"
    bl_space_type = 'VIEW_3D'
    bl_region_type = 'UI'
    bl_category = "Radiosity"

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def draw(self, context):
        layout = self.layout
        draw_solve(layout, context)
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False
        draw_oracle_and_quality(col, context, context.scene.radiosity)


class RENDER_PT_radiosity_quality(RadiosityPanel, Panel):
    """How much detail the lighting gets and where, and when the solve stops"""

    bl_label = "Quality and Limits"
    bl_parent_id = "RENDER_PT_radiosity"

    def draw(self, context):
        settings = context.scene.radiosity
        layout = split_layout(self.layout)

        col = draw_oracle_and_quality(layout, context, settings)
        col.prop(settings, "min_element_size")

        col = layout.column()
        col.prop(settings, "visibility")
        sub = col.column()
        sub.active = settings.visibility == 'SAMPLED'
        sub.prop(settings, "rays")

        col = layout.column(align=True)
        col.prop(settings, "max_elements")
        col.prop(settings, "time_budget")
        col.prop(settings, "bounces")
        unset = unset_limits_text(settings)
        if unset:
            draw_wrapped(layout, context, unset, icon='INFO')


# What a setting left at 0 means, in words (Blender shows the number only):
# (meaning, the settings it is the meaning of).
ZERO_MEANS = (("no limit", ("max_elements", "time_budget")), ("automatic", ("min_element_size",)),
              ("until converged", ("bounces",)))


def unset_limits_text(settings):
    """What the settings at 0 mean ("Elements, Time Limit at 0: no limit. ..."),
    or "" when none is."""
    parts = []
    for meaning, names in ZERO_MEANS:
        labels = [settings.bl_rna.properties[n].name for n in names if getattr(settings, n) == 0]
        if labels:
            parts.append("%s at 0: %s." % (", ".join(labels), meaning))
    return " ".join(parts)


class RENDER_PT_radiosity_output(RadiosityPanel, Panel):
    """Where the lighting is written, and colours for game engines"""

    bl_label = "Output"
    bl_parent_id = "RENDER_PT_radiosity"

    def draw(self, context):
        settings = context.scene.radiosity
        layout = split_layout(self.layout)

        col = layout.column()
        col.prop(settings, "output")
        col.prop(settings, "show_wireframe")
        col.prop(settings, "view_result")

        col = layout.column(heading="Colours")
        col.active = settings.output != 'LIGHTING'  # it keeps the materials: nothing to make unlit
        col.prop(settings, "display_colours", text="For Games")
        sub = col.column()
        sub.active = settings.display_colours
        sub.prop(settings, "display_exposure")
        layout.operator("radiosity.export_gltf", icon='EXPORT')


class RENDER_PT_radiosity_stats(RadiosityPanel, Panel):
    """What the last solve reported"""

    bl_label = "Statistics"
    bl_parent_id = "RENDER_PT_radiosity"

    def draw(self, context):
        draw_stats(self.layout, context, context.scene.radiosity.stats)


def draw_stats(layout, context, stats):
    """The last solve's statistics as labels (results, not settings), named on the left
    like the settings above them."""
    if not stats.valid:
        layout.label(text="Not solved yet", icon='INFO')
        return
    draw_wrapped(layout, context, stats.status)
    if stats.relit:
        draw_wrapped(layout, context, "Relit: only the lighting had changed", icon='LIGHT')
    elif stats.relinked_because:
        draw_wrapped(layout, context, "Linked anew: " + stats.relinked_because)
    kept = solve_reuse.kept_bytes(context.scene)
    if kept:
        # What the next Solve can start from, and the memory that costs.
        draw_wrapped(layout, context, "Kept to relight: %.0f MB" % max(kept / 2**20, 1))
    col = layout.column(align=True)
    for name, value in (("Oracle", stats.oracle),
                        ("Elements", "{:,}".format(stats.elements)),
                        ("Links", "{:,}".format(stats.links) if stats.links else "None"),
                        ("Iterations", "%d" % stats.iterations),
                        ("Time", "%.2f s" % stats.seconds)):
        split = col.split(factor=0.4)
        left = split.row()
        left.alignment = 'RIGHT'
        left.label(text=name)
        split.label(text=value)
    if no_links_text(stats):
        draw_wrapped(layout, context, no_links_text(stats), icon='INFO')
    if stats.warning:
        draw_wrapped(layout, context, stats.warning, icon='ERROR')


def no_links_text(stats):
    """Why a solve has no links ("Links 0" alone read as a failure), or ""."""
    if stats.links:
        return ""
    if stats.status == pipeline.STATUS["quality"]:
        return "No links: no two surfaces see each other, all light comes straight from the lights"
    return "No links: the solve stopped before it linked any surfaces"


# --- Menus: the Render menu and the 3D view's View menu, where F3 finds them -----------

def draw_operators(layout):
    layout.operator("radiosity.solve", icon='LIGHT_AREA')
    layout.operator("radiosity.toggle_result", icon='HIDE_OFF')
    layout.operator("radiosity.clear", icon='X')


class VIEW3D_MT_radiosity(Menu):
    """Solve the scene's radiosity, show or hide the result, remove it"""

    bl_label = "Radiosity"

    def draw(self, context):
        draw_operators(self.layout)


def draw_render_menu(self, context):
    self.layout.separator()
    draw_operators(self.layout)


def draw_export_menu(self, context):
    self.layout.operator("radiosity.export_gltf", text="Radiosity Result (.glb/.gltf)")


def draw_view_menu(self, context):
    # Beside Viewport Render: what the 3D view shows of the scene's lighting.
    self.layout.separator()
    self.layout.menu("VIEW3D_MT_radiosity")


# (menu, draw function) pairs that register() appends and unregister() removes.
MENU_ENTRIES = (("TOPBAR_MT_render", draw_render_menu), ("VIEW3D_MT_view", draw_view_menu),
                ("TOPBAR_MT_file_export", draw_export_menu))


def register():
    """After the classes: the menu entries and the fallback progress bar's property."""
    bpy.types.WindowManager.radiosity_progress = PROGRESS_PROPERTY
    for menu, function in MENU_ENTRIES:
        menu = getattr(bpy.types, menu)
        menu.remove(function)  # never twice, whatever registered before
        menu.append(function)


def unregister():
    for menu, function in MENU_ENTRIES:
        getattr(bpy.types, menu).remove(function)
    del bpy.types.WindowManager.radiosity_progress
