"""Which objects a render shows, and showing them in the viewport while the scene is read.

Cycles renders an object that is enabled in renders and lies in a collection of
the view layer that is neither excluded nor disabled in renders, nor below one
that is; whether the viewport shows it (the eye or the monitor icon, of the
object or its collections) does not matter (measured in 3.4, 4.5 and 5.0:
tests/blender/test_export.py). The export reads the viewport's depsgraph, which
holds only what the viewport shows, so `RenderedShown` shows the rendered
objects in the viewport while it reads and then puts every flag back.
"""


def rendered_collections(view_layer):
    """The layer collections of `view_layer` whose objects a render may show."""
    found = []

    def walk(layer_collection):
        if layer_collection.exclude or layer_collection.collection.hide_render:
            return
        found.append(layer_collection)
        for child in layer_collection.children:
            walk(child)

    walk(view_layer.layer_collection)
    return found


def rendered_objects(view_layer, renders):
    """The original objects of `view_layer` a render shows: those in a rendered
    collection for which `renders(object)` (its own render flag) is true."""
    return {obj for lc in rendered_collections(view_layer) for obj in lc.collection.objects if renders(obj)}


class RenderedShown:
    """Context manager: every object a render shows is shown in the viewport inside
    (with the collections it lies in), as it was on exit."""

    def __init__(self, view_layer, renders):
        self.view_layer, self.renders = view_layer, renders
        self.undo = []  # (thing, attribute or None for the eye of an object, previous value)

    def __enter__(self):
        layer = self.view_layer
        try:
            for lc in rendered_collections(layer):
                objects = [o for o in lc.collection.objects if self.renders(o)]
                if not objects:
                    continue
                # The collection and those above it: a hidden parent hides its children.
                for item in _ancestors(layer, lc):
                    self._show(item, "hide_viewport")
                    self._show(item.collection, "hide_viewport")
                for obj in objects:
                    self._show(obj, "hide_viewport")
                    if obj.hide_get(view_layer=layer):
                        self.undo.append((obj, None, True))
                        obj.hide_set(False, view_layer=layer)
            if self.undo:
                layer.update()
        except BaseException:
            self.__exit__(None, None, None)
            raise
        return self

    def _show(self, thing, attribute):
        if getattr(thing, attribute):
            self.undo.append((thing, attribute, True))
            setattr(thing, attribute, False)

    def __exit__(self, *exc):
        for thing, attribute, value in reversed(self.undo):
            if attribute is None:
                thing.hide_set(value, view_layer=self.view_layer)
            else:
                setattr(thing, attribute, value)
        self.undo = []
        return False


def _ancestors(view_layer, target):
    """The layer collections from the root down to `target`."""
    def path(lc):
        if lc == target:
            return [lc]
        for child in lc.children:
            below = path(child)
            if below:
                return [lc] + below
        return []
    return path(view_layer.layer_collection)
