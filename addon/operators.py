"""Operators of the Radiosity add-on.

`radiosity.solve` is the one entry point for users, scripts and tests. Its
execute runs the whole solve synchronously (background mode, scripts, tests);
invoke, from the UI, will later run the same solve on a worker thread with a
progress bar, so both paths share `_solve`. Every failure becomes a report and
{'CANCELLED'}, never a traceback, and leaves the scene as it was.
"""

import sys
import traceback

from bpy.types import Operator

from . import native


class SolveError(Exception):
    """A failure the user can act on; its message is reported as is."""


class RADIOSITY_OT_solve(Operator):
    """Compute the diffuse lighting of the scene with hierarchical radiosity and bake it into colour attributes"""

    bl_idname = "radiosity.solve"
    bl_label = "Solve Radiosity"
    # The solve writes meshes and attributes, so it is one undo step.
    bl_options = {'REGISTER', 'UNDO'}

    @classmethod
    def poll(cls, context):
        if context.scene is None:
            return False
        # In Edit Mode the mesh data blocks lag behind the edit meshes, so a
        # solve would silently use stale geometry.
        if context.mode != 'OBJECT':
            cls.poll_message_set("Switch to Object Mode to solve radiosity")
            return False
        return True

    def execute(self, context):
        return self._run(context)

    def invoke(self, context, event):
        # Synchronous for now; the interactive solve (worker thread, progress,
        # ESC to cancel) replaces this without changing execute.
        return self._run(context)

    def _run(self, context):
        try:
            solver = native.load()
            return self._solve(context, solver)
        except (native.NativeUnavailable, SolveError) as err:
            self.report({'ERROR'}, str(err))
        except Exception as err:
            # A bug: the traceback goes to the console for whoever fixes it,
            # the user gets a report.
            traceback.print_exc(file=sys.stderr)
            self.report({'ERROR'}, "Radiosity solve failed unexpectedly: %s: %s"
                        % (type(err).__name__, err))
        return {'CANCELLED'}

    def _solve(self, context, solver):
        """Export the scene, solve with `solver` (the native module), bake the result."""
        raise SolveError("Radiosity solver not implemented yet")

