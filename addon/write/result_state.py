"""The radiosity result's state in the scene: what is the result, what it hides.

A solve leaves its marks in the scene as custom properties (the tags below,
defined only here): the result objects and their "Radiosity" collection, the
originals hidden while the result is shown (with their state before, to be put
back), the shared "Radiosity Emission" material and the attributes written on
original meshes. Finding the result, hiding and restoring the originals,
toggling between the two and removing the result read these marks. Writing
the result is bake.py; a solve's rollback is scene_transaction.py.
"""

import json

import bpy

from . import bake_materials

# Objects the add-on itself made, which must never be solved again.
RESULT_TAG = "radiosity_result"
# Originals the add-on hid in renders, with their previous state (hide_originals).
HIDDEN_TAG = "radiosity_hidden"
# On an original mesh whose "Radiosity" attribute the add-on wrote: one of the
# user's own by that name is never overwritten or removed.
ORIGINAL_ATTRIBUTE_TAG = "radiosity_attribute"
# The shared "Radiosity Emission" material (bake.emission_material).
MATERIAL_TAG = "radiosity_material"
# On the scene, and on the window manager: how each 3D view was shaded before
# the result was shown in it (show_in_views), to be put back when the originals
# come back. The scene's copy is saved with the file; the window manager's
# outlives an undo that takes the scene back to before the result (views are
# not undone, the scene is).
VIEWS_TAG = "radiosity_views"
COLLECTION_NAME = "Radiosity"


# --- The Radiosity collection ------------------------------------------------------------

def result_collection(scene, create=True):
    """The scene's collection of result objects (made on demand)."""
    for coll in scene.collection.children_recursive:
        if coll.get(RESULT_TAG):
            return coll
    if not create:
        return None
    coll = bpy.data.collections.new(COLLECTION_NAME)
    coll[RESULT_TAG] = True
    scene.collection.children.link(coll)
    return coll


def result_objects(scene):
    """The result objects of `scene`."""
    return [o for o in scene.objects if o.get(RESULT_TAG)]


def remove_results(scene):
    """Delete the result objects and their meshes; keep the (emptied) collection."""
    for obj in result_objects(scene):
        mesh = obj.data
        bpy.data.objects.remove(obj)
        if mesh is not None and mesh.users == 0:
            bpy.data.meshes.remove(mesh)
    bake_materials.remove_unused()


# --- Showing the result instead of the originals -----------------------------------------

def hide_originals(scene, view_layer, names):
    """Hide the named originals in renders and the viewport, remembering their state."""
    for name in names:
        obj = scene.objects.get(name)
        if obj is None or obj.get(HIDDEN_TAG):
            continue
        in_layer = view_layer.objects.get(name) is not None
        obj[HIDDEN_TAG] = json.dumps({"hide_render": obj.hide_render,
                                      "hidden": obj.hide_get(view_layer=view_layer) if in_layer else False})
        obj.hide_render = True
        if in_layer:
            obj.hide_set(True, view_layer=view_layer)


def restore_originals(scene, view_layer):
    """Undo hide_originals. Returns how many objects were restored."""
    count = 0
    for obj in scene.objects:
        state = obj.get(HIDDEN_TAG)
        if not state:
            continue
        state = json.loads(state)
        obj.hide_render = state["hide_render"]
        if view_layer.objects.get(obj.name) is not None:
            obj.hide_set(state["hidden"], view_layer=view_layer)
        del obj[HIDDEN_TAG]
        count += 1
    return count


class OriginalsShown:
    """Context manager: originals the add-on hid are visible inside (the export needs them
    in the depsgraph), and hidden again on exit."""

    def __init__(self, scene, view_layer):
        self.scene, self.view_layer = scene, view_layer
        self.hidden = []

    def __enter__(self):
        self.hidden = [o.name for o in self.scene.objects if o.get(HIDDEN_TAG)]
        self.states = {n: self.scene.objects[n][HIDDEN_TAG] for n in self.hidden}
        try:
            restore_originals(self.scene, self.view_layer)
            if self.hidden:
                self.view_layer.update()
        except BaseException:  # hide them again: a failed export changes nothing
            self.__exit__(None, None, None)
            raise
        return self

    def __exit__(self, *exc):
        for name in self.hidden:
            obj = self.scene.objects.get(name)
            if obj is None:
                continue
            obj[HIDDEN_TAG] = self.states[name]
            obj.hide_render = True
            if self.view_layer.objects.get(name) is not None:
                obj.hide_set(True, view_layer=self.view_layer)
        return False


def show_results(scene, show):
    """Show or hide the result objects (render and viewport)."""
    for obj in result_objects(scene):
        obj.hide_render = not show
        obj.hide_viewport = not show


# --- The 3D views ------------------------------------------------------------------------

def _views():
    """Every 3D view, with a key that finds it again (screen name, area and space index)."""
    for screen in bpy.data.screens:
        for a, area in enumerate(screen.areas):
            for s, space in enumerate(area.spaces):
                if space.type == 'VIEW_3D':
                    yield "%s/%d/%d" % (screen.name, a, s), space


def _attribute_colour(shading):
    items = shading.bl_rna.properties["color_type"].enum_items
    return 'ATTRIBUTE' if 'ATTRIBUTE' in items else 'VERTEX'  # 'VERTEX' before Blender 3.2


def _window_manager():
    managers = bpy.data.window_managers
    return managers[0] if len(managers) else None


def _saved_views(scene):
    """How the views were shaded before the result: the scene's record, else
    the window manager's (after an undo past the solve)."""
    wm = _window_manager()
    text = scene.get(VIEWS_TAG) or (wm.get(VIEWS_TAG) if wm is not None else None)
    return json.loads(text or "{}")


def _save_views(scene, saved):
    text = json.dumps(saved)
    scene[VIEWS_TAG] = text
    wm = _window_manager()
    if wm is not None:
        wm[VIEWS_TAG] = text


def views_record(scene):
    """Both copies of the saved shading, for a rollback (scene_transaction.py)."""
    wm = _window_manager()
    return scene.get(VIEWS_TAG), wm.get(VIEWS_TAG) if wm is not None else None


def put_views_record(scene, record):
    """Puts back what views_record returned."""
    wm = _window_manager()
    for owner, text in ((scene, record[0]), (wm, record[1])):
        if owner is None:
            continue
        if text is None:
            owner.pop(VIEWS_TAG, None)
        else:
            owner[VIEWS_TAG] = text


def show_in_views(scene):
    """With "View Result" on, solid shading in every 3D view shows the result's
    colours as computed: the colour attribute, lit flat (studio lighting would
    shade them again and show them darker than the render), back faces culled
    (each side of a two-sided face is its own polygon, 2e-6 of the scene in
    front of the other: far below the depth buffer's resolution, so without
    culling the two fight and a closed box speckles). How each view was shaded
    before is saved once, for restore_views."""
    if not scene.radiosity.view_result:
        return
    saved = _saved_views(scene)
    for key, space in _views():
        shading = space.shading
        saved.setdefault(key, [shading.color_type, shading.light, shading.show_backface_culling])
        shading.color_type = _attribute_colour(shading)
        shading.light = 'FLAT'
        shading.show_backface_culling = True
    _save_views(scene, saved)


def restore_views(scene):
    """Shade the 3D views as they were before the result was shown in them."""
    saved = _saved_views(scene)
    for key, space in _views():
        if key in saved:
            shading = space.shading
            shading.color_type, shading.light, shading.show_backface_culling = saved[key]
    put_views_record(scene, (None, None))


def result_shown(scene):
    """Whether the scene shows a radiosity result (not hidden by Toggle)."""
    return any(not o.hide_viewport for o in result_objects(scene))


def sync_views(scene):
    """Shade the 3D views for what the scene shows now: the result's colours
    while a result is shown, the views as they were otherwise. Undo, redo and
    opening a file change the scene but not the views (view_sync.py)."""
    if result_shown(scene):
        show_in_views(scene)
    elif _saved_views(scene):
        restore_views(scene)


# --- Toggling and removing ---------------------------------------------------------------

def toggle(scene, view_layer):
    """Show the originals instead of the result, or the result instead of the originals."""
    if any(o.get(HIDDEN_TAG) for o in scene.objects):
        restore_originals(scene, view_layer)
        show_results(scene, False)
        restore_views(scene)
    else:
        sources = {o[RESULT_TAG] for o in result_objects(scene)}
        hide_originals(scene, view_layer, sorted(sources))
        show_results(scene, True)
        show_in_views(scene)


def anything_to_remove(scene):
    """Whether Remove Result has anything to remove: result objects, or an
    attribute written on an original."""
    return bool(result_objects(scene)) or any(
        o.type == 'MESH' and o.data.get(ORIGINAL_ATTRIBUTE_TAG) for o in scene.objects)


def clear(scene, view_layer):
    """Delete the result objects and their collection if it is left empty, and
    show the originals again (the attributes on originals: bake.remove_original_attributes)."""
    remove_results(scene)
    coll = result_collection(scene, create=False)
    if coll is not None and not coll.all_objects:
        bpy.data.collections.remove(coll)
    restore_originals(scene, view_layer)
    restore_views(scene)
