"""`gradient_small_45`: Section 4.3.1, Figure 23: occluder 45 degrees to the emitter, small emitter.

See gradient_scenes.py for the geometry.
"""

import gradient_scenes


def build(scene):
    gradient_scenes.build_gradient(scene, emitter_side=0.25, occluder_angle_degrees=45)
