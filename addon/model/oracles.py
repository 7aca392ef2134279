"""The refinement oracles: the solver's names for them and the add-on's words,
each written once.

The solver names its oracles (native/core/solve/solve_options.cpp) and the
build writes the names, in the solver's order, into solver_defaults.json. The
add-on's setting stores a name in capitals, its enum identifier
(`scene.radiosity.oracle = 'PERCEPTUAL'`): part of the scripting interface,
so a name does not change. Here each name gets the words the interface shows:
its label, what choosing it does (the menu's tooltip) and where it adds
detail (the setting's tooltip). What the Quality slider means for each is in
quality_meaning.py.
"""

from collections import namedtuple

from .solver_defaults import SOLVER_DEFAULTS

# The solver's names, in its order. Unpacked so that an oracle the solver
# adds without words here fails at import, not in a menu.
NAMES = tuple(SOLVER_DEFAULTS["oracles"])
STANDARD, PERCEPTUAL, GRADIENT, NOTICEABLE = NAMES

Wording = namedtuple("Wording", "label description adds_detail")

# Labels are short enough to show uncut at the default Properties width (the
# Blender tests measure them); descriptions say what a choice does to the
# picture and the time, with the technical name last.
WORDING = {
    STANDARD: Wording(
        "Standard",
        "Adds detail wherever much light arrives unevenly, whether or not it shows: "
        "dependable, but spends elements and time on bright areas that already look "
        "smooth (Hanrahan et al.'s BF refinement)",
        "wherever much light varies"),
    PERCEPTUAL: Wording(
        "Perceptual",
        "Adds detail only where the eye would see the shading go wrong, at shadow edges "
        "and hot spots, and leaves smooth areas coarse: the best picture for the time "
        "(Secchia 2000, judged from irradiance gradients)",
        "where the eye would notice"),
    GRADIENT: Wording(
        "Gradient",
        "Adds detail where the shading changes how quickly it brightens or darkens, as in "
        "penumbrae and light falloff (irradiance gradient difference)",
        "where the shading's slope changes"),
    NOTICEABLE: Wording(
        "Noticeable",
        "Adds detail where the mesh's shading would differ visibly from the true lighting, "
        "judged as the eye does: against the brightness around it, and less for details "
        "too small to resolve. Quality reads as a number of just noticeable differences: "
        "the fewest elements for a clean picture (Weber contrast on Secchia's gradients)",
        "where the mesh would differ visibly from the true lighting"),
}


def identifier(name):
    """The setting's enum identifier of the solver's oracle `name`."""
    return name.upper()


def name_of(identifier):
    """The solver's name of the oracle the setting's enum `identifier` stands for."""
    return identifier.lower()


IDENTIFIERS = tuple(identifier(name) for name in NAMES)
# The setting's items (identifier, label, description), in the solver's order.
ENUM_ITEMS = tuple((identifier(name), WORDING[name].label, WORDING[name].description) for name in NAMES)

# The setting's tooltip: where each oracle adds detail.
_CHOICES = ["%s (%s)" % (WORDING[name].adds_detail, WORDING[name].label) for name in NAMES]
SETTING_DESCRIPTION = ("Where the lighting gets more detail: %s or %s. Technically, the refinement oracle"
                       % (", ".join(_CHOICES[:-1]), _CHOICES[-1]))
