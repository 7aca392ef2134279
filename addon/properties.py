"""Scene settings of the Radiosity add-on: `scene.radiosity`.

What the user chooses (oracle, quality, budgets, visibility, output) and what
the last solve reported. Identifiers of enum items are part of the scripting
interface (`scene.radiosity.oracle = 'PERCEPTUAL'`); tests and batch scripts
rely on them, so they do not change.
"""

import json
import pathlib

import bpy
from bpy.props import (
    BoolProperty,
    EnumProperty,
    FloatProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)
from bpy.types import PropertyGroup

# The solver's own defaults and limits (SolveOptions{} in the native core),
# written into the package when it is built (solver_defaults.json): each is
# defined once, in C++, and the settings still register when the native
# module cannot load.
SOLVER_DEFAULTS = json.loads(pathlib.Path(__file__).with_name("solver_defaults.json").read_text())

ORACLE_ITEMS = (
    ('STANDARD', "Standard",
     "Refine where the form factor varies over the receiver times the emitter's "
     "power (Hanrahan et al. BF refinement)"),
    ('PERCEPTUAL', "Perceptual",
     "Refine where linear interpolation of radiance across an element would be "
     "visibly wrong, judged from irradiance gradients (Secchia 2000)"),
    ('GRADIENT', "Gradient Difference",
     "Refine where the irradiance gradient changes across the receiver"),
)

VISIBILITY_ITEMS = (
    ('EXACT', "Exact",
     "Clip each emitter against its occluders as seen from every sample point; "
     "exact shadows and gradients, slower"),
    ('SAMPLED', "Sampled",
     "Estimate the visible fraction of each emitter with shadow rays; faster, "
     "noisier penumbrae, gradients ignore occluders"),
)

OUTPUT_ITEMS = (
    ('REFINED', "Refined Meshes",
     "Write new meshes that carry the adaptive refinement into a 'Radiosity' "
     "collection, leaving the originals untouched"),
    ('ORIGINAL', "Original Meshes",
     "Write a face-corner 'Radiosity' colour attribute onto the original meshes, "
     "without refinement"),
    ('BOTH', "Both",
     "Write refined meshes and the attribute on the original meshes"),
    ('LIGHTING', "Lighting Only (Keep Materials)",
     "Write refined meshes like Refined Meshes, each with copies of its original's "
     "materials (textures included) lit by the solution's 'Radiosity Light' attribute "
     "(the light before the surface's colour); the originals are untouched"),
)


class RadiosityStats(PropertyGroup):
    """What the last solve of this scene reported. Written by the solver, shown read-only."""

    valid: BoolProperty(
        name="Solved",
        description="Whether this scene has been solved since the settings were created",
        default=False,
    )
    status: StringProperty(
        name="Status",
        description="How the last solve ended (converged, budget reached, cancelled)",
    )
    oracle: StringProperty(
        name="Oracle",
        description="Refinement oracle used by the last solve",
    )
    elements: IntProperty(
        name="Elements",
        description="Leaf elements of the hierarchy after the last solve",
        min=0,
    )
    links: IntProperty(
        name="Links",
        description="Interaction links after the last solve",
        min=0,
    )
    iterations: IntProperty(
        name="Iterations",
        description="Refine-gather-push/pull iterations of the last solve",
        min=0,
    )
    seconds: FloatProperty(
        name="Time",
        description="Wall-clock time of the last solve",
        min=0.0,
        unit='TIME_ABSOLUTE',
    )
    warning: StringProperty(
        name="Warning",
        description="What the last solve could not model (for example point lights)",
    )

    def clear(self):
        """Forget the last solve."""
        self.valid = False
        self.status = self.oracle = self.warning = ""
        self.elements = self.links = self.iterations = 0
        self.seconds = 0.0


def _update_wireframe(settings, context):
    # Imported here: bake needs bpy data that registration does not.
    from . import bake
    bake.set_wireframe(settings.id_data, settings.show_wireframe)


class RadiositySettings(PropertyGroup):
    """Radiosity solver settings of a scene."""

    oracle: EnumProperty(
        name="Oracle",
        description="How the solver decides where to refine the mesh",
        items=ORACLE_ITEMS,
        default=SOLVER_DEFAULTS["oracle"].upper(),
    )
    quality: FloatProperty(
        name="Quality",
        description=(
            "How finely to refine, from 0 (coarse and fast) to 1 (fine and slow). "
            "Each oracle maps it to its own refinement threshold relative to the "
            "scene's emitted power and area, so the same value gives comparable "
            "results in scenes of any scale or brightness"
        ),
        min=0.0,
        max=1.0,
        default=SOLVER_DEFAULTS["quality"],
        subtype='FACTOR',
    )
    max_elements: IntProperty(
        name="Max Elements",
        description=(
            "Stop refining when the hierarchy has this many leaf elements and "
            "keep the best solution so far (0 for no limit)"
        ),
        min=0,
        default=0,
    )
    time_budget: FloatProperty(
        name="Time Budget",
        description=(
            "Stop after about this many seconds, reading the scene and writing the result "
            "included, and keep the best solution so far (0 for no limit)"
        ),
        min=0.0,
        default=0.0,
        unit='TIME_ABSOLUTE',
    )
    min_element_size: FloatProperty(
        name="Smallest Element",
        description=(
            "Elements are not split below this edge length (0: automatic, elements down "
            "to 1/%s of the scene's surface area). The perceptual and gradient "
            "oracles refine the thin shadows of chair and table legs down to this "
            "size at any quality, so in furnished rooms it sets their cost"
        ) % format(round(1.0 / SOLVER_DEFAULTS["min_element_area"]), ","),
        min=0.0,
        default=0.0,
        subtype='DISTANCE',
    )
    visibility: EnumProperty(
        name="Visibility",
        description="How occlusion between surfaces is computed",
        items=VISIBILITY_ITEMS,
        default=SOLVER_DEFAULTS["visibility"].upper(),
    )
    rays: IntProperty(
        name="Rays",
        description="Shadow rays per sample point and emitter for sampled visibility",
        min=1,
        soft_max=256,
        max=SOLVER_DEFAULTS["max_rays"],
        default=SOLVER_DEFAULTS["rays"],
    )
    bounces: IntProperty(
        name="Bounces",
        description=(
            "Number of refine-gather-push/pull iterations (0 to iterate until "
            "the radiance converges)"
        ),
        min=0,
        soft_max=16,
        default=0,
    )
    output: EnumProperty(
        name="Output",
        description="Where the solution is written",
        items=OUTPUT_ITEMS,
        default='REFINED',
    )
    show_wireframe: BoolProperty(
        name="Show Elements",
        description="Show the edges of the refined elements in the viewport",
        default=False,
        update=_update_wireframe,
    )
    # Game-ready colours (issue 15; game_export.py, display_colours.py).
    display_colours: BoolProperty(
        name="Game-Ready Colours",
        description=(
            "Bake display-ready colours for game engines instead of radiance: exposure, "
            "the scene's view transform (Color Management) and a clamp to 0-1, shown "
            "through an unlit material that the glTF exporter writes as KHR_materials_unlit "
            "with the colours as COLOR_0 (not with Lighting Only, which keeps the materials)"
        ),
        default=False,
    )
    display_exposure: FloatProperty(
        name="Exposure",
        description=(
            "Exposure of the game-ready colours in stops (radiance times 2^exposure), "
            "added to the scene's Color Management exposure"
        ),
        soft_min=-10.0,
        soft_max=10.0,
        default=0.0,
    )
    view_result: BoolProperty(
        name="View Result",
        description=(
            "Show the result in Solid shading as it will render: colour attribute, flat "
            "lighting. Your shading settings come back when you toggle or remove the result"
        ),
        default=True,
    )
    stats: PointerProperty(type=RadiosityStats)

    def solver_options(self):
        """The settings as plain values, the form the native solver takes."""
        return {
            "oracle": self.oracle.lower(),
            "quality": self.quality,
            "max_elements": self.max_elements,
            "time_budget": self.time_budget,
            "visibility": self.visibility.lower(),
            "rays": self.rays,
            "bounces": self.bounces,
            "min_element_size": self.min_element_size,
        }

