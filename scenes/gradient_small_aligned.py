"""`gradient_small_aligned`: Section 4.3.1, Figure 25: occluder aligned with the emitter, small emitter.

See gradient_scenes.py for the geometry.
"""

import gradient_scenes


def build(scene):
    gradient_scenes.build_gradient(scene, emitter_side=0.25, occluder_angle_degrees=0)
