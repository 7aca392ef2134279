"""Writing the result into the scene: meshes and colour attributes (bake.py),
materials (bake_materials.py, game_ready.py), what is the result and what it
hides (result_state.py), all of it as one transaction (scene_transaction.py),
and the glTF export of the result (gltf_export.py)."""
