"""The four scenes of the source's Section 4.3.1 (Figures 21-25), shared code.

An emitter, an occluder and a receiver in parallel planes (Figure 21): the
receiver a 3.2 m square at z = 0 facing up, the occluder a 0.6 m square at
z = 1, the emitter a square at z = 2 facing down, 1 m (large) or 0.25 m
(small) on a side, with the same power either way; the occluder's edges
parallel to the emitter's (aligned) or turned 45 degrees. The same geometry
as `make figures` (native/tools/visibility_figures.cpp), which plots F and
|grad F| on the receiver; solving these scenes shows where each oracle
refines around the penumbra and the discontinuity lines. No room: a black
world, so the receiver sees only the emitter (and the occluder's shadow).
"""

import math

import numpy as np

import scene_kit as kit

RECEIVER = 3.2
OCCLUDER = 0.6
POWER_RADIANCE_AREA = 10.0   # emitter radiance x area, the same for both sizes

WHITE = (0.75, 0.75, 0.75)
GREY = (0.5, 0.5, 0.5)


def square(side, z, angle, facing_down):
    """(vertices, quads) of a square centred on the z axis at height z, turned by `angle`."""
    h = side / 2
    corners = np.array([[-h, -h], [h, -h], [h, h], [-h, h]])
    c, s = math.cos(angle), math.sin(angle)
    xy = corners @ np.array([[c, s], [-s, c]])
    verts = np.column_stack([xy, np.full(4, z)])
    quad = [0, 3, 2, 1] if facing_down else [0, 1, 2, 3]
    return verts, np.array([quad])


def build_gradient(scene, emitter_side, occluder_angle_degrees):
    kit.add_mesh(scene, "Receiver", square(RECEIVER, 0.0, 0.0, False), kit.diffuse_material("Receiver", WHITE))
    kit.add_mesh(scene, "Occluder", square(OCCLUDER, 1.0, math.radians(occluder_angle_degrees), False),
                 kit.diffuse_material("Occluder", GREY))
    strength = POWER_RADIANCE_AREA / emitter_side ** 2
    kit.add_mesh(scene, "Light", square(emitter_side, 2.0, 0.0, True), kit.emission_material("Light", strength))
    kit.add_camera(scene, location=(0.0, -3.2, 2.8), target=(0.0, 0.0, 0.0), lens=28.0)
    kit.setup_render(scene)
