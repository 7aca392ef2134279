"""Keeps the 3D views' shading in step with the result through undo, redo and
opening a file.

Blender's undo takes the scene back (the result objects come and go) but not
the screens: after undoing a solve the views stayed flat-shaded by the colour
attribute, so the originals drew flat white; after undoing Remove Result the
result came back in Studio lighting, grey. After each of these events the
views are shaded for what the scene shows (result_state.sync_views).
"""

import bpy
from bpy.app.handlers import persistent

from ..write import result_state


@persistent
def _sync(*_args):
    scene = bpy.context.scene
    if scene is not None:
        result_state.sync_views(scene)


HANDLERS = (bpy.app.handlers.undo_post, bpy.app.handlers.redo_post, bpy.app.handlers.load_post)


def attach(function, handler_lists):
    """Adds `function` to each of bpy.app.handlers' `handler_lists` once."""
    for handlers in handler_lists:
        if function not in handlers:
            handlers.append(function)


def detach(function, handler_lists):
    for handlers in handler_lists:
        if function in handlers:
            handlers.remove(function)


def register():
    attach(_sync, HANDLERS)


def unregister():
    detach(_sync, HANDLERS)
