"""`full_office`: the office with a chair, shelves and a cabinet (high occlusion).

The office scene (office.py) plus a chair pulled up to the table, a tall
open shelf unit against the left wall and a closed cabinet against the back
wall: many small occluders close to each other and to the walls, the case
where hierarchical radiosity spends most of its links.
"""

import office
import scene_kit as kit

WOOD_DARK = (0.3, 0.18, 0.1)
FABRIC = (0.15, 0.2, 0.35)
LIGHT_GREY = (0.6, 0.6, 0.58)


def add_chair(scene, x, y, fabric, metal):
    """A chair facing +y: seat 0.45 m high, backrest behind it, four legs."""
    seat, seat_h = (0.45, 0.45, 0.05), 0.45
    kit.add_mesh(scene, "Chair.Seat", kit.box(seat), fabric, location=(x, y, seat_h - seat[2] / 2))
    kit.add_mesh(scene, "Chair.Back", kit.box((0.45, 0.04, 0.45)), fabric,
                 location=(x, y - 0.205, seat_h + 0.225))
    leg_h = seat_h - seat[2]
    leg = kit.box((0.03, 0.03, leg_h), omit=("top", "bottom"))
    for i, (sx, sy) in enumerate(((-1, -1), (1, -1), (1, 1), (-1, 1)), start=1):
        kit.add_mesh(scene, "Chair.Leg.%d" % i, leg, metal,
                     location=(x + sx * 0.19, y + sy * 0.19, leg_h / 2))


def add_shelves(scene, x, y, wood):
    """An open shelf unit 0.35 m deep, 1.2 m wide, 2 m high, its back to the left wall (-x)."""
    depth, width, height, board = 0.35, 1.2, 2.0, 0.03
    for i, sy in enumerate((-1, 1), start=1):
        kit.add_mesh(scene, "Shelves.Side.%d" % i, kit.box((depth, board, height), omit=("bottom",)), wood,
                     location=(x, y + sy * (width - board) / 2, height / 2))
    inner = width - 2 * board
    for i, z in enumerate((0.1, 0.55, 1.0, 1.45, 1.985), start=1):
        kit.add_mesh(scene, "Shelves.Board.%d" % i, kit.box((depth, inner, board)), wood,
                     location=(x, y, z))


def add_cabinet(scene, x, y, colour):
    """A closed cabinet 0.8 x 0.45 x 1.1 m, its back to the back wall (+y)."""
    size = (0.8, 0.45, 1.1)
    kit.add_mesh(scene, "Cabinet", kit.box(size, omit=("bottom", "back")), colour,
                 location=(x, y, size[2] / 2))


def build(scene):
    office.build(scene)
    metal = kit.diffuse_material("Chair Metal", office.METAL)
    add_chair(scene, 0.1, -0.35, kit.diffuse_material("Fabric", FABRIC), metal)
    lo, hi = office.ROOM_LO, office.ROOM_HI
    add_shelves(scene, lo[0] + 0.175 + 0.01, 0.2, kit.diffuse_material("Dark Wood", WOOD_DARK))
    add_cabinet(scene, 1.6, hi[1] - 0.225 - 0.01, kit.diffuse_material("Cabinet", LIGHT_GREY))
