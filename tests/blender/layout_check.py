"""A stand-in for bpy.types.UILayout that checks every call a panel makes.

UILayout cannot be constructed in background mode (layouts exist only while a
window region draws), so a panel's draw() is exercised with this object instead.
It is strict where real drawing would only print a console warning: method
names and keyword arguments must exist in UILayout's RNA definition, attributes
set on it must be UILayout properties, `prop` must name an existing property of
its data, `operator` a registered operator, `menu` a registered menu, and icons
must be known icons.

It also keeps what was drawn as a tree of layouts, so that `overflows(width)`
can tell which texts Blender would cut ("Smallest Ele...") in a region of that
width: each text measured with blf in the UI font, against the room Blender's
layout gives it (a row shares its width, property split gives labels 40 %,
checkboxes, drop-downs and icons take their part). The room was measured in
Blender 3.4's Properties editor under Xvfb (tests/blender/panel_screenshot.py
shows the real thing): texts of known width in a panel at region widths 192
and 248, where they start to be cut.
"""

import types

import blf
import bpy

_RNA = bpy.types.UILayout.bl_rna
_ICONS = set(_RNA.functions["label"].parameters["icon"].enum_items.keys())
# Methods that return a nested layout.
_SUBLAYOUTS = {"column", "row", "box", "split", "column_flow", "grid_flow"}

# The Properties editor's region in the factory layout of a 1280x800 window
# (Blender 3.4; 248 at 1600x900, 303 at 1920x1080), the window the screenshot
# test uses: the width labels must fit.
DEFAULT_REGION_WIDTH = 192
# What a panel's layout is narrower than its region, and the room texts need
# beyond their own width (pixels at UI scale 1; calibrated in 3.4, see above).
PANEL_MARGIN = 33
SPLIT_FACTOR = 0.4     # use_property_split: the label column's share
LABEL_PAD = 5          # around a label's or a button's text
ICON = 20              # an icon before a text
CHECKBOX = 28          # a checkbox and its gap before the text
DROPDOWN = 26          # a drop-down's arrow and padding
SLIDER_VALUE = 40      # a slider's value ("43%") beside its text
BOX_PAD = 10           # a box's inner margins
UI_TEXT_SIZE = 11      # points of the UI font at scale 1


def text_width(text):
    """Width in pixels of `text` in the UI font at scale 1 (DejaVu Sans in 3.x, Inter since 4.0)."""
    try:
        blf.size(0, UI_TEXT_SIZE)
    except TypeError:  # before 4.0: size(fontid, size, dpi)
        blf.size(0, UI_TEXT_SIZE, 72)
    return blf.dimensions(0, text)[0]


def layout_width(region_width=DEFAULT_REGION_WIDTH):
    """The width of a panel's layout in a Properties region `region_width` wide."""
    return region_width - PANEL_MARGIN


class FakeContext:
    """bpy.context as a panel sees it while drawing in a region `region_width` wide."""

    def __init__(self, region_width=DEFAULT_REGION_WIDTH, context=None):
        self.region = types.SimpleNamespace(width=region_width, type='WINDOW')
        self._context = context or bpy.context

    def __getattr__(self, name):
        return getattr(self._context, name)


class CheckedLayout:
    """Records what is drawn: `props` (data, name), `operators`, `labels`, `menus`,
    and the tree of layouts for `overflows`."""

    def __init__(self, record=None, kind="panel", args=None, split=False):
        self.__dict__["_record"] = record if record is not None else {
            "props": [], "operators": [], "labels": [], "menus": [], "layouts": 0}
        self.__dict__["_attrs"] = {"use_property_split": split}
        self.__dict__["_kind"] = kind
        self.__dict__["_args"] = args or {}
        # ("layout", CheckedLayout) or ("text", role, text, icon) in drawing order.
        self.__dict__["_items"] = []

    @property
    def record(self):
        return self._record

    def __setattr__(self, name, value):
        if name not in _RNA.properties:
            raise AttributeError("UILayout has no property %r" % name)
        self._attrs[name] = value

    def __getattr__(self, name):
        if name in self._attrs:
            return self._attrs[name]
        if name in _RNA.properties:
            return _RNA.properties[name].default
        if name not in _RNA.functions:
            raise AttributeError("UILayout has no function %r" % name)
        function = _RNA.functions[name]
        inputs = [p for p in function.parameters if not p.is_output]
        names = [p.identifier for p in inputs]

        def call(*args, **kwargs):
            if len(args) > len(names):
                raise TypeError("%s() takes at most %d positional arguments" % (name, len(names)))
            for key in kwargs:
                if key not in names:
                    raise TypeError("%s() got an unexpected keyword argument %r" % (name, key))
            bound = dict(zip(names, args), **kwargs)
            for p in inputs:
                if p.is_required and p.identifier not in bound:
                    raise TypeError("%s() missing required argument %r" % (name, p.identifier))
            icon = bound.get("icon")
            if icon is not None and icon not in _ICONS:
                raise ValueError("%s(): unknown icon %r" % (name, icon))
            return self._handle(name, bound)

        return call

    def _text(self, role, text, icon='NONE'):
        if text:
            self._items.append(("text", role, text, icon))

    def _handle(self, name, bound):
        if name in _SUBLAYOUTS:
            self._record["layouts"] += 1
            child = type(self)(self._record, name, bound, self.use_property_split)
            self._items.append(("layout", child))
            return child
        icon = bound.get("icon", 'NONE')
        if name == "prop":
            data, prop = bound["data"], bound["property"]
            if prop not in data.bl_rna.properties:
                raise AttributeError("%s has no property %r" % (data.bl_rna.identifier, prop))
            self._record["props"].append((data, prop))
            self._prop_texts(data, data.bl_rna.properties[prop], bound)
        elif name == "operator":
            idname = bound["operator"]
            module, _, op = idname.partition(".")
            try:
                rna = getattr(getattr(bpy.ops, module), op).get_rna_type()
            except (AttributeError, KeyError):
                raise AttributeError("unknown operator %r" % idname) from None
            self._record["operators"].append(idname)
            self._text("button", bound.get("text", rna.name), icon)
            return _OperatorProperties()
        elif name == "menu":
            menu = getattr(bpy.types, bound["menu"], None)
            if menu is None or not issubclass(menu, bpy.types.Menu):
                raise AttributeError("unknown menu %r" % bound["menu"])
            self._record["menus"].append(bound["menu"])
            self._text("button", bound.get("text", menu.bl_label), icon)
        elif name == "label":
            self._record["labels"].append(bound.get("text", ""))
            self._text("label", bound.get("text", ""), icon)
        elif name == "progress":
            self._record["labels"].append(bound.get("text", ""))
            self._text("bar", bound.get("text", ""))
        return None

    def _prop_texts(self, data, rna, bound):
        """The texts a property's button shows, by the room each gets."""
        text = bound.get("text", rna.name)
        value = None
        if rna.type == 'ENUM' and not rna.is_enum_flag and not bound.get("expand"):
            items = rna.enum_items
            current = getattr(data, rna.identifier)
            value = items[current].name if current in items else None
        if rna.type == 'BOOLEAN' and not bound.get("toggle"):
            heading = self._args.get("heading", "")
            if self.use_property_split:
                self._text("split_label", heading)
                self._text("split_checkbox", text)
            else:
                self._text("checkbox", text)
        elif self.use_property_split:
            self._text("split_label", text)
            if value is not None:
                self._text("split_dropdown", value)
        elif value is not None:
            self._text("dropdown", value)
        elif bound.get("slider"):
            self._text("slider", text)
        else:
            self._text("field", text)

    def overflows(self, width=None):
        """[(text, its width, the room it has)] of every text Blender would cut when this
        layout is `width` pixels wide (default: a panel's at DEFAULT_REGION_WIDTH)."""
        width = layout_width() if width is None else width
        cut = []
        if self._kind == "box":
            width -= BOX_PAD
        shares = self._shares(width)
        for (kind, *item), room in zip(self._items, shares):
            if kind == "layout":
                cut += item[0].overflows(room)
                continue
            role, text, icon = item
            need = text_width(text) + (ICON if icon != 'NONE' else 0)
            have = _room(role, room)
            if need > have:
                cut.append((text, need, round(have, 1)))
        return cut

    def _shares(self, width):
        """The width each item gets: a row shares it, a split gives its first item
        the factor, a column (and an automatic grid flow, which has as many columns
        as fit its widest item) gives each all of it."""
        count = len(self._items)
        if self._kind == "row" and count:
            return [width / count] * count
        if self._kind == "split" and count:
            factor = self._args.get("factor", 0.0) or 1.0 / count
            rest = width * (1.0 - factor) / max(1, count - 1)
            return [width * factor] + [rest] * (count - 1)
        if self._kind in ("grid_flow", "column_flow") and self._args.get("columns", 0) > 0:
            return [width / self._args["columns"]] * count
        return [width] * count


def _room(role, width):
    """The room for a text of `role` in a button `width` wide."""
    label_column = width * SPLIT_FACTOR
    value_column = width - label_column
    return {
        "split_label": label_column - LABEL_PAD,
        "split_checkbox": value_column - CHECKBOX,
        "split_dropdown": value_column - DROPDOWN,
        "checkbox": width - CHECKBOX,
        "dropdown": width - DROPDOWN,
        "slider": width - SLIDER_VALUE,
        "field": width - SLIDER_VALUE,
    }.get(role, width - LABEL_PAD)


class _OperatorProperties:
    """What `operator()` returns: accepts property assignments."""

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)


class FakePanel:
    """What a Panel's draw() needs from `self`."""

    def __init__(self, layout):
        self.layout = layout
