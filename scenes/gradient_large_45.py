"""`gradient_large_45`: Section 4.3.1, Figure 22: occluder 45 degrees to the emitter, large emitter.

See gradient_scenes.py for the geometry.
"""

import gradient_scenes


def build(scene):
    gradient_scenes.build_gradient(scene, emitter_side=1.0, occluder_angle_degrees=45)
