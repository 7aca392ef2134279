// The measures of one polygon that the scene's checks, the kernels and contact
// meshing all take: one definition each.
#pragma once

#include <algorithm>
#include <cmath>
#include <span>

#include "radiosity/vec.h"

namespace radiosity {

// The z of the 3D cross product of two vectors in a plane.
inline double cross2(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }

// Area of a plane polygon, positive when counter-clockwise.
inline double signed_area(std::span<const dvec2> polygon) {
  double a = 0.0;
  for (std::size_t i = 0, k = polygon.size(); i < k; ++i)
    a += cross2(polygon[i], polygon[(i + 1) % k]);
  return 0.5 * a;
}

// Twice the area vector: the fan of cross products about corner 0, whose
// length is twice the area and whose direction is the front normal of
// counter-clockwise corners. Taken relative to corner 0, so a small polygon
// far from the origin keeps its digits.
inline dvec3 twice_area_normal(std::span<const dvec3> polygon) {
  dvec3 sum(0.0);
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i)
    sum += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  return sum;
}

// The largest distance between two corners.
inline double polygon_diameter(std::span<const dvec3> polygon) {
  double d = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
    for (std::size_t j = i + 1; j < polygon.size(); ++j)
      d = std::max(d, glm::length(polygon[j] - polygon[i]));
  return d;
}

// The centre of cell (i, j) of an n x n grid over a quad (bilinear in its
// corners) or a triangle (the square folded onto it along its diagonal, which
// keeps the points uniform): where coarse checks look between an element's
// corners and centre.
inline dvec3 grid_point(const dvec3* corners, int corner_count, int i, int j, int n) {
  double a = (i + 0.5) / n, b = (j + 0.5) / n;
  const dvec3* c = corners;
  if (corner_count == 4)
    return (1 - a) * (1 - b) * c[0] + a * (1 - b) * c[1] + a * b * c[2] + (1 - a) * b * c[3];
  if (a + b > 1.0) a = 1.0 - a, b = 1.0 - b;
  return (1 - a - b) * c[0] + a * c[1] + b * c[2];
}

// Does the polygon enclose area beyond rounding? Its area normal must exceed
// 1e-12 of the square of its extent from the first corner: zero-area,
// collinear and coincident polygons do not, and the kernels need them not to
// reach them (MATH.md s3). The bindings and the fuzzers check with this.
inline bool encloses_area(std::span<const dvec3> polygon) {
  double extent = 0.0;
  for (std::size_t i = 1; i < polygon.size(); ++i)
    extent = std::max(extent, glm::length(polygon[i] - polygon[0]));
  const double area = glm::length(twice_area_normal(polygon));
  return std::isfinite(area) && area > 1e-12 * extent * extent && extent > 0.0;
}

}  // namespace radiosity
