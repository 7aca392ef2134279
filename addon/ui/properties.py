"""Scene settings of the Radiosity add-on: `scene.radiosity`.

What the user chooses (oracle, quality, budgets, visibility, output) and what
the last solve reported. Identifiers of enum items are part of the scripting
interface (`scene.radiosity.oracle = 'PERCEPTUAL'`); tests and batch scripts
rely on them, so they do not change.
"""

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

from ..model import oracles
from ..model.solver_defaults import SOLVER_DEFAULTS

VISIBILITY_ITEMS = (
    ('EXACT', "Exact",
     "Shadows computed exactly wherever they can show: clean edges and smooth "
     "penumbrae; slower in cluttered scenes (each light clipped against its "
     "occluders). With the Standard and Noticeable oracles, light under a "
     "fiftieth of what a surface gathers is shadowed with rays"),
    ('SAMPLED', "Sampled",
     "Shadows estimated with rays: faster in cluttered scenes, slightly noisy "
     "penumbrae (more Rays, less noise), and shadow edges may get less detail "
     "(the oracles' gradients ignore occluders)"),
)

OUTPUT_ITEMS = (
    ('REFINED', "New Meshes",
     "Adds lit copies of the objects, finely divided where the light changes, in a "
     "'Radiosity' collection and shows them instead of the originals, which stay "
     "untouched (Toggle Result switches back)"),
    ('ORIGINAL', "On Originals",
     "Stores the light on the original meshes as a 'Radiosity' colour attribute: no "
     "new objects, but only as much detail as the meshes' own vertices"),
    ('BOTH', "Both",
     "New meshes, and the colour attribute on the original meshes"),
    ('LIGHTING', "Lit Materials",
     "Like New Meshes, but each copy keeps its original's materials and textures, lit "
     "by the solution: the surface colour comes from the material, the light from "
     "the solve ('Radiosity Light' attribute); the originals are untouched"),
)


class RadiosityStats(PropertyGroup):
    """What the last solve of this scene reported. Written by the solver, shown read-only."""

    valid: BoolProperty(
        name="Solved",
        description="Whether this scene has been solved since its settings were made",
        default=False,
    )
    status: StringProperty(
        name="Status",
        description="How the last solve ended: converged, stopped at a limit, or cancelled",
    )
    oracle: StringProperty(
        name="Oracle",
        description="The oracle the last solve used",
    )
    elements: IntProperty(
        name="Elements",
        description="Elements (mesh pieces) of the last solve's result",
        min=0,
    )
    links: IntProperty(
        name="Links",
        description="Pairs of elements the last solve exchanged light between (links)",
        min=0,
    )
    iterations: IntProperty(
        name="Iterations",
        description="Light-gathering iterations of the last solve (refine-gather-push/pull)",
        min=0,
    )
    seconds: FloatProperty(
        name="Time",
        description="How long the last solve took",
        min=0.0,
        unit='TIME_ABSOLUTE',
    )
    relit: BoolProperty(
        name="Relit",
        description=(
            "The last solve started from the elements and links of the one before it: only "
            "lights, emission or colours had changed"
        ),
        default=False,
    )
    relinked_because: StringProperty(
        name="Linked Anew",
        description="Why the last solve could not start from the one before it",
    )
    warning: StringProperty(
        name="Warning",
        description="What the last solve could not model (for example point lights), and other notes",
    )

    def clear(self):
        """Forget the last solve."""
        self.valid = False
        self.status = self.oracle = self.warning = self.relinked_because = ""
        self.elements = self.links = self.iterations = 0
        self.seconds = 0.0
        self.relit = False


def _update_wireframe(settings, context):
    # Imported here: bake needs bpy data that registration does not.
    from ..write import bake
    bake.set_wireframe(settings.id_data, settings.show_wireframe)


class RadiositySettings(PropertyGroup):
    """Radiosity solver settings of a scene."""

    oracle: EnumProperty(
        name="Oracle",
        description=oracles.SETTING_DESCRIPTION,
        items=oracles.ENUM_ITEMS,
        default=oracles.identifier(SOLVER_DEFAULTS["oracle"]),
    )
    quality: FloatProperty(
        name="Quality",
        description=(
            "How much detail the lighting gets: low values are fast, with soft, blocky "
            "shadows; high values resolve sharp shadow edges and small features but take "
            "much longer and make heavier meshes. The same value looks alike in scenes of "
            "any size or brightness (each oracle's threshold is relative to the scene's "
            "emitted power and area)"
        ),
        min=0.0,
        max=1.0,
        default=SOLVER_DEFAULTS["quality"],
        subtype='FACTOR',
    )
    max_elements: IntProperty(
        name="Elements",
        description=(
            "Most elements (pieces of the result's meshes) to make: the solve stops adding "
            "detail there and keeps the best lighting so far, which bounds its memory, the "
            "mesh size and the time. 0: no limit"
        ),
        min=0,
        default=0,
    )
    time_budget: FloatProperty(
        name="Time Limit",
        description=(
            "Stop after about this many seconds, reading the scene and writing the result "
            "included, and keep the best lighting so far. 0: no limit"
        ),
        min=0.0,
        default=0.0,
        unit='TIME_ABSOLUTE',
    )
    min_element_size: FloatProperty(
        name="Min Size",
        description=(
            "Surfaces are never divided finer than this edge length. Raise it to save time "
            "in furnished rooms: the Perceptual and Gradient oracles follow the thin shadows "
            "of chair and table legs down to this size at any quality. 0: automatic, "
            "elements down to 1/%s of the scene's surface area"
        ) % format(round(1.0 / SOLVER_DEFAULTS["min_element_area"]), ","),
        min=0.0,
        default=0.0,
        subtype='DISTANCE',
    )
    visibility: EnumProperty(
        name="Visibility",
        description="How shadows are computed: exactly, or estimated with rays",
        items=VISIBILITY_ITEMS,
        default=SOLVER_DEFAULTS["visibility"].upper(),
    )
    rays: IntProperty(
        name="Rays",
        description=(
            "Rays from each point toward each light, for Sampled visibility: more give "
            "smoother penumbrae and take longer"
        ),
        min=1,
        soft_max=256,
        max=SOLVER_DEFAULTS["max_rays"],
        default=SOLVER_DEFAULTS["rays"],
    )
    # Scripts set it as `bounces`; the UI does not call it that, since Cycles' Bounces
    # count reflections and its 0 means direct light only.
    bounces: IntProperty(
        name="Iterations",
        description=(
            "Not Cycles' light bounces. 0 (the default) repeats until the lighting has "
            "converged, adding detail pass by pass: the full solution. A number N runs one "
            "pass of exactly N light-gathering iterations, so light reflects at most N times "
            "(1: direct light only): quicker, but darker where light arrives indirectly. "
            "Technically, refine-gather-push/pull iterations"
        ),
        min=0,
        soft_max=16,
        default=0,
    )
    output: EnumProperty(
        name="Output",
        description="Where the lighting is written: new meshes, the originals, or both",
        items=OUTPUT_ITEMS,
        default='REFINED',
    )
    show_wireframe: BoolProperty(
        name="Wireframe",
        description=(
            "Show the edges of the result's elements in the viewport, to see where the "
            "solve added detail"
        ),
        default=False,
        update=_update_wireframe,
    )
    # Game-ready colours (issue 15; write/game_ready.py, model/display_colours.py).
    display_colours: BoolProperty(
        name="Game-Ready Colours",
        description=(
            "Bake colours ready to show in a game engine instead of light values: exposure "
            "and the scene's view transform (Color Management) applied, clamped to 0-1 and "
            "shown unlit, exported to glTF as vertex colours (COLOR_0 with "
            "KHR_materials_unlit). Not with Lit Materials, which keeps the materials"
        ),
        default=False,
    )
    display_exposure: FloatProperty(
        name="Exposure",
        description=(
            "Brightens (positive) or darkens (negative) the game-ready colours, in stops "
            "(radiance times 2^exposure), on top of the scene's Color Management exposure"
        ),
        soft_min=-10.0,
        soft_max=10.0,
        default=0.0,
    )
    view_result: BoolProperty(
        name="View Result",
        description=(
            "Show the result in Solid shading as it will render: colour attribute, flat "
            "lighting, back faces hidden. Your shading settings come back when you toggle "
            "or remove the result"
        ),
        default=True,
    )
    stats: PointerProperty(type=RadiosityStats)

    def solver_options(self):
        """The settings as plain values, the form the native solver takes."""
        return {
            "oracle": oracles.name_of(self.oracle),
            "quality": self.quality,
            "max_elements": self.max_elements,
            "time_budget": self.time_budget,
            "visibility": self.visibility.lower(),
            "rays": self.rays,
            "bounces": self.bounces,
            "min_element_size": self.min_element_size,
        }

