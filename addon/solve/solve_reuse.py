"""The last complete solve of each scene, kept for relighting (the native
SolveReuse).

Solving again a scene whose geometry and solve settings are unchanged, after
only lights, emission or colours changed, starts from the kept elements and
links instead of linking anew: form factors and shadows depend on the
geometry alone. Kept in memory only (never in the .blend), one per scene;
forgotten on Remove Result, when a file is loaded and when the add-on is
unregistered. The native module compares the geometry itself, so a kept solve
that no longer fits is never used, only replaced.
"""

import bpy
from bpy.app.handlers import persistent

_kept = {}  # scene (its data-block pointer) -> SolveReuse


def for_scene(solver, scene):
    """The scene's SolveReuse (empty until a solve completes with it)."""
    key = scene.as_pointer()
    reuse = _kept.get(key)
    if reuse is None:
        reuse = _kept[key] = solver.SolveReuse()
    return reuse


def kept_bytes(scene):
    """Memory the scene's kept solve holds (0 when none)."""
    reuse = _kept.get(scene.as_pointer())
    return reuse.memory_bytes if reuse is not None else 0


def forget(scene=None):
    """Free the kept solve of `scene`, or of every scene. A solve running with
    it keeps its own reference until it ends."""
    if scene is None:
        _kept.clear()
    else:
        _kept.pop(scene.as_pointer(), None)


@persistent
def _forget_all(*_args):
    forget()


def register():
    bpy.app.handlers.load_pre.append(_forget_all)


def unregister():
    if _forget_all in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_forget_all)
    forget()
