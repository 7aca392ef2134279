"""The polygons of a solver result and their areas: plain numpy, no module
import, so the Blender tests measure results the same way."""

import numpy as np


def polygons(result):
    """Vertex index arrays of the result's polygons."""
    offsets = np.concatenate([[0], np.cumsum(result.face_sizes)])
    return [result.face_vertices[offsets[i]:offsets[i + 1]] for i in range(len(result.face_sizes))]


def polygon_areas(result):
    areas = []
    for poly in polygons(result):
        p = result.positions[poly]
        areas.append(0.5 * np.linalg.norm(np.cross(p[1:-1] - p[0], p[2:] - p[0]).sum(axis=0)))
    return np.array(areas)


def lit_mean_irradiance(result):
    """The area weighted mean gathered H over the lit polygons. A side that
    sees nothing (the outside of a closed room, the inside of a box) is dark,
    1e-4 of the light or less, and whether it is output at all turns on links
    of 1e-11 through the room's seams: left out."""
    areas = polygon_areas(result)
    lit = result.irradiance.max(axis=1) > 1e-3 * result.irradiance.max()
    return (result.irradiance[lit] * areas[lit, None]).sum(axis=0) / areas[lit].sum()
