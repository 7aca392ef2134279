"""The solver's defaults, limits and choices (SolveOptions{} and the names of
its options' values in the native core), written into the package when it is
built (solver_defaults.json): each is defined once, in C++, and the add-on's
settings still register when the native module cannot load."""

import json
import pathlib

SOLVER_DEFAULTS = json.loads((pathlib.Path(__file__).parent.parent / "solver_defaults.json").read_text())
