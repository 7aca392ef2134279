"""Reading the Blender scene into the solver's arrays (export.py), with what a
render shows (render_visibility.py). Blender glue; the array work is model/."""
