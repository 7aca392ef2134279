"""Writing a solve into the scene as one transaction.

A solve changes the scene in several steps: it replaces the result objects
(and their lighting copies of materials), hides the originals, writes the
"Radiosity" attribute onto original meshes and switches the 3D views to
attribute colours. Any step can fail (a bug, a full memory, an object Blender
refuses to change); the user must then find the scene exactly as it was, the
previous result included. `SceneTransaction` records what the steps touch;
on an exception it puts every bit of it back, on success it deletes the
previous result for good.
"""

import bpy

from .. import compat
from . import bake, bake_materials, result_state
from .result_state import HIDDEN_TAG, ORIGINAL_ATTRIBUTE_TAG, RESULT_TAG

RETIRED_SUFFIX = " (previous radiosity result)"


def _views():
    for screen in bpy.data.screens:
        for area in screen.areas:
            for space in area.spaces:
                if space.type == 'VIEW_3D':
                    yield space


class SceneTransaction:
    """with SceneTransaction(scene, view_layer) as t: ... t.retire_results() ...

    Inside, the previous result objects are only retired (unlinked, renamed,
    kept in bpy.data) so the new ones can take their names."""

    def __init__(self, scene, view_layer):
        self.scene, self.view_layer = scene, view_layer
        self.retired = []  # (object, name, mesh name)
        self.retired_materials = []  # (material, name)

    def __enter__(self):
        scene, layer = self.scene, self.view_layer
        self.had_collection = result_state.result_collection(scene, create=False) is not None
        self.objects = set(bpy.data.objects)
        self.meshes = set(bpy.data.meshes)
        self.materials = set(bpy.data.materials)
        self.visibility = {}
        for obj in scene.objects:
            in_layer = layer.objects.get(obj.name) is not None
            self.visibility[obj] = (obj.hide_render, obj.hide_viewport, obj.get(HIDDEN_TAG),
                                    obj.hide_get(view_layer=layer) if in_layer else None)
        self.attributes = {}
        for obj in scene.objects:
            if obj.type == 'MESH' and not obj.get(RESULT_TAG) and obj.data not in self.attributes:
                attr = obj.data.color_attributes.get(bake.ATTRIBUTE)
                self.attributes[obj.data] = (None if attr is None else _copy_attribute(attr),
                                             obj.data.get(ORIGINAL_ATTRIBUTE_TAG))
        self.shading = [(space, space.shading.color_type, space.shading.light,
                         space.shading.show_backface_culling) for space in _views()]
        self.saved_views = result_state.views_record(scene)
        return self

    def retire_results(self):
        """Take the previous result objects out of the scene, keeping them for a rollback."""
        coll = result_state.result_collection(self.scene, create=False)
        if coll is None:
            return
        for obj in list(coll.objects):
            if not obj.get(RESULT_TAG):
                continue
            self.retired.append((obj, obj.name, obj.data.name if obj.data is not None else None))
            for slot in obj.material_slots:
                m = slot.material
                if m is not None and m.get(bake_materials.COPY_TAG) is not None and \
                        all(m is not r for r, _ in self.retired_materials):
                    self.retired_materials.append((m, m.name))
            coll.objects.unlink(obj)
        # Free the names for the new result (lighting copies included); set_name,
        # since a user's object may already carry a retired name.
        for obj, name, mesh_name in self.retired:
            compat.set_name(bpy.data.objects, obj, name + RETIRED_SUFFIX)
            if obj.data is not None:
                compat.set_name(bpy.data.meshes, obj.data, mesh_name + RETIRED_SUFFIX)
        for material, name in self.retired_materials:
            compat.set_name(bpy.data.materials, material, name + RETIRED_SUFFIX)

    def __exit__(self, kind, error, trace):
        if kind is None:
            self._commit()
        else:
            self._rollback()
        return False

    def _commit(self):
        for obj, _, _ in self.retired:
            mesh = obj.data
            bpy.data.objects.remove(obj)
            if mesh is not None and mesh.users == 0:
                bpy.data.meshes.remove(mesh)
        bake_materials.remove_unused()

    def _rollback(self):
        # What the failed steps made goes first, so that the old names are free.
        for obj in [o for o in bpy.data.objects if o not in self.objects]:
            bpy.data.objects.remove(obj)
        for mesh in [m for m in bpy.data.meshes if m not in self.meshes and m.users == 0]:
            bpy.data.meshes.remove(mesh)
        for material in [m for m in bpy.data.materials if m not in self.materials and m.users == 0]:
            bpy.data.materials.remove(material)
        for material, name in self.retired_materials:
            compat.set_name(bpy.data.materials, material, name)
        coll = result_state.result_collection(self.scene, create=not self.had_collection and bool(self.retired))
        for obj, name, mesh_name in self.retired:
            compat.set_name(bpy.data.objects, obj, name)
            if obj.data is not None:
                compat.set_name(bpy.data.meshes, obj.data, mesh_name)
            if coll is not None and obj.name not in coll.objects:
                coll.objects.link(obj)
        if not self.had_collection and coll is not None and not self.retired and len(coll.objects) == 0:
            bpy.data.collections.remove(coll)
        layer = self.view_layer
        for obj, (hide_render, hide_viewport, tag, hidden) in self.visibility.items():
            obj.hide_render, obj.hide_viewport = hide_render, hide_viewport
            if tag is None:
                if HIDDEN_TAG in obj:
                    del obj[HIDDEN_TAG]
            else:
                obj[HIDDEN_TAG] = tag
            if hidden is not None and layer.objects.get(obj.name) is not None:
                obj.hide_set(hidden, view_layer=layer)
        for mesh, (saved, tag) in self.attributes.items():
            if tag is None:
                mesh.pop(ORIGINAL_ATTRIBUTE_TAG, None)
            else:
                mesh[ORIGINAL_ATTRIBUTE_TAG] = tag
            attrs = mesh.color_attributes
            current = attrs.get(bake.ATTRIBUTE)
            if current is not None:
                attrs.remove(current)
            if saved is not None:
                data_type, domain, values = saved
                attr = attrs.new(bake.ATTRIBUTE, data_type, domain)
                attr.data.foreach_set("color", values)
        for space, colour, light, culling in self.shading:
            shading = space.shading
            shading.color_type, shading.light, shading.show_backface_culling = colour, light, culling
        result_state.put_views_record(self.scene, self.saved_views)


def _copy_attribute(attr):
    values = [0.0] * (4 * len(attr.data))
    attr.data.foreach_get("color", values)
    return attr.data_type, attr.domain, values
