"""`gradient_large_aligned`: Section 4.3.1, Figure 24: occluder aligned with the emitter, large emitter.

See gradient_scenes.py for the geometry.
"""

import gradient_scenes


def build(scene):
    gradient_scenes.build_gradient(scene, emitter_side=1.0, occluder_angle_degrees=0)
