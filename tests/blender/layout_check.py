"""A stand-in for bpy.types.UILayout that checks every call a panel makes.

UILayout cannot be constructed in background mode (layouts exist only while a
window region draws), so a panel's draw() is exercised with this object instead.
It is strict where real drawing would only print a console warning: method
names and keyword arguments must exist in UILayout's RNA definition, attributes
set on it must be UILayout properties, `prop` must name an existing property of
its data, `operator` a registered operator, and icons must be known icons.
"""

import bpy

_RNA = bpy.types.UILayout.bl_rna
_ICONS = set(_RNA.functions["label"].parameters["icon"].enum_items.keys())
# Methods that return a nested layout.
_SUBLAYOUTS = {"column", "row", "box", "split", "column_flow", "grid_flow"}


class CheckedLayout:
    """Records what is drawn: `props` (data, name), `operators`, `labels`."""

    def __init__(self, record=None):
        self.__dict__["_record"] = record if record is not None else {
            "props": [], "operators": [], "labels": [], "layouts": 0}
        self.__dict__["_attrs"] = {}

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

    def _handle(self, name, bound):
        if name in _SUBLAYOUTS:
            self._record["layouts"] += 1
            return CheckedLayout(self._record)
        if name == "prop":
            data, prop = bound["data"], bound["property"]
            if prop not in data.bl_rna.properties:
                raise AttributeError("%s has no property %r" % (data.bl_rna.identifier, prop))
            self._record["props"].append((data, prop))
        elif name == "operator":
            idname = bound["operator"]
            module, _, op = idname.partition(".")
            try:
                getattr(getattr(bpy.ops, module), op).get_rna_type()
            except (AttributeError, KeyError):
                raise AttributeError("unknown operator %r" % idname) from None
            self._record["operators"].append(idname)
            return _OperatorProperties()
        elif name == "label":
            self._record["labels"].append(bound.get("text", ""))
        return None


class _OperatorProperties:
    """What `operator()` returns: accepts property assignments."""

    def __setattr__(self, name, value):
        object.__setattr__(self, name, value)


class FakePanel:
    """What a Panel's draw() needs from `self`."""

    def __init__(self, layout):
        self.layout = layout
