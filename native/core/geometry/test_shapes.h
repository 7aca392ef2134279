// Shared helpers for the kernel tests: closed forms, random configurations and
// finite differences.
#pragma once

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "radiosity/vec.h"

namespace radiosity::test {

// Parallel rectangle a x b at height c, receiver below one corner (MATH.md s5).
inline double corner_parallel(double a, double b, double c) {
  const double x = a / c, y = b / c;
  const double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  return (x / sx * std::atan(y / sx) + y / sy * std::atan(x / sy)) * kInvTwoPi;
}

// Rectangle of width b and height a perpendicular to the receiver plane, sharing
// a line at distance c from the receiver point.
inline double perpendicular(double a, double b, double c) {
  const double h = std::sqrt(a * a + c * c);
  return (std::atan(b / c) - c / h * std::atan(b / h)) * kInvTwoPi;
}

// Axis-aligned rectangle [x0, x1] x [y0, y1] at height z facing down (-z),
// counter-clockwise about -z.
inline std::vector<dvec3> rectangle_facing_down(double x0, double x1, double y0, double y1,
                                                double z) {
  return {{x0, y0, z}, {x0, y1, z}, {x1, y1, z}, {x1, y0, z}};
}

inline dvec3 central_difference(const std::function<double(const dvec3&)>& f, const dvec3& r,
                                double h) {
  dvec3 g;
  for (int k = 0; k < 3; ++k) {
    dvec3 step(0.0);
    step[k] = h;
    g[k] = (f(r + step) - f(r - step)) / (2 * h);
  }
  return g;
}

// A random emitter polygon and a receiver facing it somewhat.
struct RandomConfiguration {
  std::vector<dvec3> polygon;  // counter-clockwise about `emitter_normal`
  dvec3 emitter_normal;
  dvec3 point;
  dvec3 normal;
  double scale;  // distance between receiver and emitter centre
};

inline dvec3 random_unit(std::mt19937_64& rng) {
  std::normal_distribution<double> normal(0.0, 1.0);
  dvec3 v;
  do v = {normal(rng), normal(rng), normal(rng)};
  while (glm::length(v) < 1e-3);
  return glm::normalize(v);
}

// Orthonormal tangents (t1, t2) with t1 x t2 = n.
inline void tangent_frame(const dvec3& n, dvec3& t1, dvec3& t2) {
  const dvec3 helper = std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  t1 = glm::normalize(glm::cross(helper, n));
  t2 = glm::cross(n, t1);
}

// Star-shaped polygon around `centre` in the plane of `n`: convex when `convex`,
// else with random radii (non-convex in general).
inline std::vector<dvec3> random_polygon(std::mt19937_64& rng, const dvec3& centre, const dvec3& n,
                                         double size, bool convex) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::uniform_int_distribution<int> count(3, 9);
  dvec3 t1, t2;
  tangent_frame(n, t1, t2);
  const int k = count(rng);
  std::vector<double> angles(k);
  for (double& a : angles) a = uniform(rng) * 2 * kPi;
  std::sort(angles.begin(), angles.end());
  const double rx = size * (0.3 + uniform(rng)), ry = size * (0.3 + uniform(rng));
  std::vector<dvec3> polygon;
  for (int i = 0; i < k; ++i) {
    const double radius = convex ? 1.0 : 0.35 + 0.65 * uniform(rng);
    polygon.push_back(centre +
                      radius * (rx * std::cos(angles[i]) * t1 + ry * std::sin(angles[i]) * t2));
  }
  return polygon;
}

inline RandomConfiguration random_configuration(std::mt19937_64& rng, bool convex = true) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  RandomConfiguration c;
  c.emitter_normal = random_unit(rng);
  const dvec3 centre = {uniform(rng) * 4 - 2, uniform(rng) * 4 - 2, uniform(rng) * 4 - 2};
  const double size = 0.2 + 1.5 * uniform(rng);
  c.polygon = random_polygon(rng, centre, c.emitter_normal, size, convex);
  // Receiver in front of the emitter, at a distance comparable to its size.
  dvec3 direction;
  do direction = random_unit(rng);
  while (glm::dot(direction, c.emitter_normal) < 0.15);
  c.scale = size * (0.5 + 3 * uniform(rng));
  c.point = centre + c.scale * direction;
  // Any normal that sees some of the emitter, including grazing ones: the
  // emitter may straddle the horizon.
  const dvec3 towards_emitter = glm::normalize(centre - c.point);
  do c.normal = random_unit(rng);
  while (glm::dot(c.normal, towards_emitter) < -0.3);
  return c;
}

}  // namespace radiosity::test
