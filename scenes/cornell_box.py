"""`cornell_box`: the Cornell box from its published geometry, Lambertian, with the
light a small gap under the ceiling (0.1 mm by default), as people model it.

Source of every number here: Cornell University Program of Computer Graphics,
"Cornell Box Data" (www.graphics.cornell.edu/online/box/data.html): the walls,
the light and the two blocks as vertex lists in millimetres (y up, the camera
looking along +z), the camera (position 278 273 -800, direction +z, focal
length 35 mm, film 25 x 25 mm) and the measured reflectance spectra (white,
green, red; 400-700 nm in 4 nm steps; all surfaces Lambertian) and the light's
emission spectrum (0, 8, 15.6, 18.4 at 400, 500, 600, 700 nm). As published:
the floor is 3.2 mm wider at the front than at the back, the left (red) wall
is a slightly non-planar quad (here its two triangles, as Blender renders it,
so that every face is planar), the blocks have five faces each (no bottom)
and stand on the floor, and the front of the box is open (a black world
outside). The published light lies in the ceiling's plane; here it hangs
`gap` below it (a mesh with an Emission shader, which Cycles lets emit from
both sides), so the ceiling behind it is lit by the light's back.

Colours: the published spectra converted to linear Rec. 709 RGB (the sRGB
primaries Blender renders in) under CIE illuminant D65 with the CIE 1931 2-degree
observer, integrated over 400-700 nm (computed with colour-science 0.4.7:
sd_to_XYZ, XYZ_to_RGB); the light's spectrum to the same RGB, normalised to
luminance 1 (a warm light: Blender's Standard view shows it orange-white).

Coordinates: Blender's (X, Y, Z) = (-x, z, y) / 1000, a rotation (z up, the
camera looking along +Y from -Y, the red wall on the left at X = -0.556).
"""

import numpy as np

import scene_kit as kit

# The light's published height is the ceiling's (548.8 mm); this gap moves it down.
GAP = 1e-4   # metres: 0.1 mm

WHITE = (0.7363, 0.7367, 0.7379)
GREEN = (0.0677, 0.3989, 0.0862)
RED = (0.4923, 0.0490, 0.0511)
LIGHT_COLOUR = (1.675, 0.8777, 0.224)
# Luminance of the light's radiance: chosen (not published) so that the back
# wall renders at about 0.2-0.4 under the Standard view transform.
LIGHT_STRENGTH = 30.0

# Published vertex lists (mm), in their published order (each face counter-clockwise
# seen from inside the box, or from outside a block).
FLOOR = ((552.8, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 559.2), (549.6, 0.0, 559.2))
CEILING = ((556.0, 548.8, 0.0), (556.0, 548.8, 559.2), (0.0, 548.8, 559.2), (0.0, 548.8, 0.0))
BACK_WALL = ((549.6, 0.0, 559.2), (0.0, 0.0, 559.2), (0.0, 548.8, 559.2), (556.0, 548.8, 559.2))
RIGHT_WALL = ((0.0, 0.0, 559.2), (0.0, 0.0, 0.0), (0.0, 548.8, 0.0), (0.0, 548.8, 559.2))
LEFT_WALL = ((552.8, 0.0, 0.0), (549.6, 0.0, 559.2), (556.0, 548.8, 559.2), (556.0, 548.8, 0.0))
LIGHT = ((343.0, 548.8, 227.0), (343.0, 548.8, 332.0), (213.0, 548.8, 332.0), (213.0, 548.8, 227.0))
SHORT_BLOCK = (
    ((130.0, 165.0, 65.0), (82.0, 165.0, 225.0), (240.0, 165.0, 272.0), (290.0, 165.0, 114.0)),
    ((290.0, 0.0, 114.0), (290.0, 165.0, 114.0), (240.0, 165.0, 272.0), (240.0, 0.0, 272.0)),
    ((130.0, 0.0, 65.0), (130.0, 165.0, 65.0), (290.0, 165.0, 114.0), (290.0, 0.0, 114.0)),
    ((82.0, 0.0, 225.0), (82.0, 165.0, 225.0), (130.0, 165.0, 65.0), (130.0, 0.0, 65.0)),
    ((240.0, 0.0, 272.0), (240.0, 165.0, 272.0), (82.0, 165.0, 225.0), (82.0, 0.0, 225.0)),
)
TALL_BLOCK = (
    ((423.0, 330.0, 247.0), (265.0, 330.0, 296.0), (314.0, 330.0, 456.0), (472.0, 330.0, 406.0)),
    ((423.0, 0.0, 247.0), (423.0, 330.0, 247.0), (472.0, 330.0, 406.0), (472.0, 0.0, 406.0)),
    ((472.0, 0.0, 406.0), (472.0, 330.0, 406.0), (314.0, 330.0, 456.0), (314.0, 0.0, 456.0)),
    ((314.0, 0.0, 456.0), (314.0, 330.0, 456.0), (265.0, 330.0, 296.0), (265.0, 0.0, 296.0)),
    ((265.0, 0.0, 296.0), (265.0, 330.0, 296.0), (423.0, 330.0, 247.0), (423.0, 0.0, 247.0)),
)
CAMERA_POSITION = (278.0, 273.0, -800.0)
CAMERA_LENS, CAMERA_FILM = 35.0, 25.0   # mm


def to_blender(points_mm):
    """Published millimetres (y up) to Blender metres (z up)."""
    p = np.asarray(points_mm, dtype=float) / 1000.0
    return np.stack([-p[..., 0], p[..., 2], p[..., 1]], axis=-1)


def add_faces(scene, name, faces_mm, material, drop=0.0):
    """One object of the given published polygons, its origin at its centre (so
    the object's location says where it is), moved down by `drop` metres."""
    sizes = [len(face) for face in faces_mm]
    corners = to_blender(np.array([corner for face in faces_mm for corner in face], dtype=float))
    # Corners shared by a block's faces become one vertex (a connected mesh).
    verts, index = np.unique(np.round(corners, 9), axis=0, return_inverse=True)
    starts = np.cumsum([0] + sizes)
    faces = [index.reshape(-1)[a:b].tolist() for a, b in zip(starts[:-1], starts[1:])]
    centre = verts.mean(axis=0)
    return kit.add_mesh(scene, name, (verts - centre, faces), material,
                        location=tuple(centre - np.array([0.0, 0.0, drop])))


def as_triangles(quad):
    """A non-planar quad as the two triangles Blender renders it as (corners 0 1 2
    and 0 2 3), so that the mesh is the published surface with planar faces."""
    return [(quad[0], quad[1], quad[2]), (quad[0], quad[2], quad[3])]


def build(scene, gap=GAP):
    white = kit.lambertian_material("White", WHITE)
    red = kit.lambertian_material("Red", RED)
    green = kit.lambertian_material("Green", GREEN)
    for name, faces, mat in (("Floor", [FLOOR], white), ("Ceiling", [CEILING], white),
                             ("Wall.Back", [BACK_WALL], white), ("Wall.Right", [RIGHT_WALL], green),
                             ("Wall.Left", as_triangles(LEFT_WALL), red)):
        add_faces(scene, name, faces, mat)
    add_faces(scene, "Block.Short", SHORT_BLOCK, white)
    add_faces(scene, "Block.Tall", TALL_BLOCK, white)
    # Colour inputs are kept within [0, 1]: the colour's brightest channel goes into the strength.
    peak = max(LIGHT_COLOUR)
    light = kit.emission_material("Light", LIGHT_STRENGTH * peak, tuple(c / peak for c in LIGHT_COLOUR))
    add_faces(scene, "Light", [LIGHT], light, drop=gap)
    scene["light_gap"] = gap

    cam = kit.add_camera(scene, location=tuple(to_blender(CAMERA_POSITION)),
                         target=tuple(to_blender((278.0, 273.0, 0.0))), lens=CAMERA_LENS)
    cam.data.sensor_fit = 'HORIZONTAL'
    cam.data.sensor_width = CAMERA_FILM
    kit.setup_render(scene, resolution=(512, 512))
