"""What goes to the solver and comes back from it, without bpy: the arrays of
the scene and the result (arrays.py, surface_uv.py), the units of Blender's
lights (light_units.py), display colours (display_colours.py), the solver's defaults
and choices (solver_defaults.py), the oracles' names and words (oracles.py),
and the words for what the solver reports (findings.py, progress_text.py,
quality_meaning.py).
Importable and tested in plain Python (tests/model)."""
