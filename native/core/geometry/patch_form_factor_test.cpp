// Patch-to-patch form factor against catalogue closed forms, reciprocity,
// cubature of the point kernel, closure of boxes, invariances and degenerate
// configurations.
#include "core/geometry/patch_form_factor.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <glm/gtc/matrix_transform.hpp>
#include <limits>
#include <random>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/test_shapes.h"

namespace radiosity {
namespace {

using Polygon = std::vector<dvec3>;

double area(const Polygon& polygon) {
  dvec3 n(0.0);
  for (size_t i = 1; i + 1 < polygon.size(); ++i) {
    n += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  }
  return 0.5 * glm::length(n);
}

double relative_error(double actual, double expected) {
  return std::abs(actual - expected) / std::abs(expected);
}

// Quad c, c + u, c + u + v, c + v: counter-clockwise about u x v.
Polygon quad(const dvec3& c, const dvec3& u, const dvec3& v) {
  return {c, c + u, c + u + v, c + v};
}

// --- Closed forms (Howell's catalogue), in long double so that the reference's
// own cancellation at large distances stays below the tolerance. ---------------

// C-11: directly opposed parallel rectangles a x b at distance c.
double parallel_rectangles(long double a, long double b, long double c) {
  const long double x = a / c, y = b / c;
  const long double sx = std::sqrt(1 + x * x), sy = std::sqrt(1 + y * y);
  const long double bracket = 0.5L * std::log((1 + x * x) * (1 + y * y) / (1 + x * x + y * y)) +
                              x * sy * std::atan(x / sy) + y * sx * std::atan(y / sx) -
                              x * std::atan(x) - y * std::atan(y);
  return static_cast<double>(2 * bracket / (3.14159265358979323846264338L * x * y));
}

// C-14: from a rectangle of width w to a perpendicular one of height h sharing
// their common edge of length l.
double perpendicular_rectangles(long double w, long double h, long double l) {
  const long double W = w / l, H = h / l, W2 = W * W, H2 = H * H, R = std::sqrt(W2 + H2);
  const long double log_term = std::log((1 + W2) * (1 + H2) / (1 + W2 + H2)) +
                               W2 * std::log(W2 * (1 + W2 + H2) / ((1 + W2) * (W2 + H2))) +
                               H2 * std::log(H2 * (1 + H2 + W2) / ((1 + H2) * (H2 + W2)));
  const long double f =
      W * std::atan(1 / W) + H * std::atan(1 / H) - R * std::atan(1 / R) + 0.25L * log_term;
  return static_cast<double>(f / (3.14159265358979323846264338L * W));
}

Polygon floor_rectangle(double x0, double x1, double y0, double y1) {
  return quad({x0, y0, 0}, {x1 - x0, 0, 0}, {0, y1 - y0, 0});  // faces +z
}

TEST(PatchFormFactor, ParallelOpposedRectanglesMatchC11) {
  double worst = 0.0;
  for (auto [a, b, c] : {std::array{1.0, 1.0, 1.0},
                         {1.0, 1.0, 0.1},
                         {2.0, 0.5, 0.7},
                         {0.2, 3.0, 1.5},
                         {1.0, 1.0, 3.0},
                         {1.0, 2.0, 10.0},
                         {1.0, 1.0, 100.0}}) {
    const Polygon p = floor_rectangle(-a / 2, a / 2, -b / 2, b / 2);
    const Polygon q = test::rectangle_facing_down(-a / 2, a / 2, -b / 2, b / 2, c);
    const double error = relative_error(patch_form_factor(p, q), parallel_rectangles(a, b, c));
    EXPECT_LT(error, 1e-8) << a << " x " << b << " at " << c;
    worst = std::max(worst, error);
  }
  EXPECT_NEAR(parallel_rectangles(1, 1, 1), 0.1998249, 1e-7);  // the catalogue's own value
  std::printf("C-11 worst relative error %.2e\n", worst);
}

TEST(PatchFormFactor, PerpendicularSharedEdgeMatchesC14) {
  double worst = 0.0;
  for (auto [w, h, l] : {std::array{1.0, 1.0, 1.0},
                         {2.0, 1.0, 1.0},
                         {1.0, 3.0, 0.5},
                         {0.1, 1.0, 2.0},
                         {5.0, 0.2, 1.0},
                         {1.0, 1.0, 20.0}}) {
    const Polygon p = floor_rectangle(0, w, 0, l);
    const Polygon q = quad({0, 0, 0}, {0, l, 0}, {0, 0, h});  // wall x = 0 facing +x
    const double expected = perpendicular_rectangles(w, h, l);
    const double error = relative_error(patch_form_factor(p, q), expected);
    EXPECT_LT(error, 1e-8) << w << ", " << h << ", " << l;
    // And from the wall back, by reciprocity of the closed form.
    EXPECT_LT(relative_error(patch_form_factor(q, p), expected * w / h), 1e-8);
    worst = std::max(worst, error);
  }
  EXPECT_NEAR(perpendicular_rectangles(1, 1, 1), 0.2000438, 1e-7);
  std::printf("C-14 worst relative error %.2e\n", worst);
}

// --- Random configurations -----------------------------------------------------

// Convex triangle or quad inscribed in a random ellipse around `centre`,
// counter-clockwise about `normal`.
Polygon random_convex(std::mt19937_64& rng, const dvec3& centre, const dvec3& normal, double size) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  dvec3 t1, t2;
  test::tangent_frame(normal, t1, t2);
  const int count = uniform(rng) < 0.5 ? 3 : 4;
  std::vector<double> angles(count);
  for (double& a : angles) a = uniform(rng) * 2 * kPi;
  std::sort(angles.begin(), angles.end());
  const double rx = size * (0.4 + uniform(rng)), ry = size * (0.4 + uniform(rng));
  Polygon polygon;
  for (double a : angles) polygon.push_back(centre + rx * std::cos(a) * t1 + ry * std::sin(a) * t2);
  if (area(polygon) < 0.05 * size * size) return random_convex(rng, centre, normal, size);
  return polygon;
}

// A polygon on the other side of p's edge a -> b, at dihedral angle `angle`
// (pi/2: a wall on a floor), partly overlapping the edge (T-junctions) or
// sharing it exactly.
Polygon hinged(std::mt19937_64& rng, const Polygon& p, size_t edge, double angle) {
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const dvec3 a = p[edge], b = p[(edge + 1) % p.size()];
  const dvec3 n = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
  const dvec3 inward = glm::normalize(glm::cross(n, b - a));
  const dvec3 out = std::cos(angle) * inward + std::sin(angle) * n;
  const bool exact = uniform(rng) < 0.5;
  const dvec3 from = exact ? b : a + (1.3 - 0.6 * uniform(rng)) * (b - a);
  const dvec3 to = exact ? a : a + (0.3 - 0.6 * uniform(rng)) * (b - a);
  const double height = 0.3 + 1.5 * uniform(rng);
  if (uniform(rng) < 0.5) return {from, to, 0.5 * (from + to) + height * out};
  return {from, to, to + height * out + 0.2 * (uniform(rng) - 0.5) * (b - a), from + height * out};
}

struct Pair {
  Polygon p, q;
};

// 500 pairs: free (some straddling each other's plane) and hinged ones.
std::vector<Pair> random_pairs(uint64_t seed, int count) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::vector<Pair> pairs;
  while (static_cast<int>(pairs.size()) < count) {
    Pair pair;
    pair.p = random_convex(rng, dvec3(0.0), test::random_unit(rng), 0.3 + uniform(rng));
    if (uniform(rng) < 0.3) {
      const size_t edge = static_cast<size_t>(uniform(rng) * static_cast<double>(pair.p.size()));
      pair.q =
          hinged(rng, pair.p, std::min(edge, pair.p.size() - 1), 0.05 + (kPi - 0.1) * uniform(rng));
    } else {
      const dvec3 centre = (0.2 + 2.0 * uniform(rng)) * test::random_unit(rng);
      pair.q = random_convex(rng, centre, test::random_unit(rng), 0.3 + uniform(rng));
    }
    pairs.push_back(pair);
  }
  return pairs;
}

TEST(PatchFormFactor, ReciprocityOverRandomConfigurations) {
  double worst = 0.0;
  int facing = 0;
  for (const Pair& pair : random_pairs(7, 500)) {
    const double pq = area(pair.p) * patch_form_factor(pair.p, pair.q);
    const double qp = area(pair.q) * patch_form_factor(pair.q, pair.p);
    ASSERT_TRUE(std::isfinite(pq) && std::isfinite(qp));
    ASSERT_GE(pq, 0.0);
    if (pq == 0.0 && qp == 0.0) continue;
    ++facing;
    const double error = std::abs(pq - qp) / std::max(pq, qp);
    EXPECT_LT(error, 1e-8) << "pair " << facing;
    worst = std::max(worst, error);
  }
  EXPECT_GT(facing, 200);
  std::printf("reciprocity: %d facing pairs, worst relative error %.2e\n", facing, worst);
}

// Gauss-Legendre on [0, 1] for the reference cubature.
void gauss_legendre(int n, std::vector<double>& x, std::vector<double>& w) {
  x.assign(n, 0.0);
  w.assign(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double z = std::cos(kPi * (i + 0.75) / (n + 0.5)), dp = 1.0;
    for (int it = 0; it < 100; ++it) {
      double p0 = 1.0, p1 = z;
      for (int k = 2; k <= n; ++k) {
        const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
        p0 = p1;
        p1 = p2;
      }
      dp = n * (z * p1 - p0) / (z * z - 1);
      z -= p1 / dp;
    }
    x[i] = 0.5 * (1 - z);
    w[i] = 1.0 / ((1 - z * z) * dp * dp);
  }
}

// F_pq by integrating the point kernel over p with n x n Gauss on fan triangles.
double point_kernel_cubature(const Polygon& p, const Polygon& q, int n) {
  std::vector<double> x, w;
  gauss_legendre(n, x, w);
  const dvec3 normal = glm::normalize(glm::cross(p[1] - p[0], p[2] - p[0]));
  double total = 0.0;
  for (size_t k = 1; k + 1 < p.size(); ++k) {
    const dvec3 e1 = p[k] - p[0], e2 = p[k + 1] - p[0];
    double sum = 0.0;
    for (int i = 0; i < n; ++i) {
      for (int j = 0; j < n; ++j) {
        sum += w[i] * w[j] * x[i] *
               form_factor(p[0] + x[i] * ((1 - x[j]) * e1 + x[j] * e2), normal, q);
      }
    }
    total += glm::length(glm::cross(e1, e2)) * sum;
  }
  return total / area(p);
}

double polygon_distance_lower_bound(const Polygon& p, const Polygon& q) {
  auto ball = [](const Polygon& polygon, dvec3& centre) {
    centre = dvec3(0.0);
    for (const dvec3& v : polygon) centre += v;
    centre /= static_cast<double>(polygon.size());
    double radius = 0.0;
    for (const dvec3& v : polygon) radius = std::max(radius, glm::length(v - centre));
    return radius;
  };
  dvec3 cp, cq;
  const double rp = ball(p, cp), rq = ball(q, cq);
  return (glm::length(cp - cq) - rp - rq) / std::max(rp, rq);
}

TEST(PatchFormFactor, AgreesWithCubatureOfPointKernel) {
  // Separated pairs wholly in front of each other, from the near-field range of
  // the contour form (gap 0.3 radii) out to the far-field quadrature.
  std::mt19937_64 rng(11);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  double worst = 0.0;
  int tested = 0;
  while (tested < 60) {
    const dvec3 np = test::random_unit(rng);
    const Polygon p = random_convex(rng, dvec3(0.0), np, 0.5);
    const dvec3 direction = test::random_unit(rng);
    if (glm::dot(direction, np) < 0.3) continue;
    const dvec3 centre = (1.5 + 6.0 * uniform(rng) * uniform(rng)) * direction;
    dvec3 nq = test::random_unit(rng);
    if (glm::dot(nq, direction) > -0.3) continue;
    const Polygon q = random_convex(rng, centre, nq, 0.5);
    bool whole = true;  // no clipping, so the cubature integrand is smooth
    for (const dvec3& v : q) whole &= glm::dot(v - p[0], np) > 0;
    for (const dvec3& v : p) whole &= glm::dot(v - q[0], nq) > 0;
    if (!whole || polygon_distance_lower_bound(p, q) < 0.3) continue;
    const double expected = point_kernel_cubature(p, q, 40);
    const double error = relative_error(patch_form_factor(p, q), expected);
    EXPECT_LT(error, 1e-6) << "pair " << tested;
    worst = std::max(worst, error);
    ++tested;
  }
  std::printf("point-kernel cubature: worst relative error %.2e\n", worst);
}

// --- Closure of boxes ------------------------------------------------------------

// The six faces of [0,X] x [0,Y] x [0,Z], each facing inward, each split into
// an uneven grid of quads (splits differ between faces: T-junctions).
std::vector<Polygon> box_faces(const dvec3& size, bool split) {
  const double X = size.x, Y = size.y, Z = size.z;
  const std::array<std::array<dvec3, 3>, 6> faces = {{
      {dvec3(0, 0, 0), dvec3(X, 0, 0), dvec3(0, Y, 0)},
      {dvec3(0, 0, Z), dvec3(0, Y, 0), dvec3(X, 0, 0)},
      {dvec3(0, 0, 0), dvec3(0, Y, 0), dvec3(0, 0, Z)},
      {dvec3(X, 0, 0), dvec3(0, 0, Z), dvec3(0, Y, 0)},
      {dvec3(0, 0, 0), dvec3(0, 0, Z), dvec3(X, 0, 0)},
      {dvec3(0, Y, 0), dvec3(X, 0, 0), dvec3(0, 0, Z)},
  }};
  std::vector<Polygon> polygons;
  for (int f = 0; f < 6; ++f) {
    const auto& [corner, u, v] = faces[f];
    const int nu = split ? 1 + f % 3 : 1, nv = split ? 2 - f % 2 + (f == 4) : 1;
    auto cut = [&](int k, int n) {  // uneven: cuts pulled towards 0
      const double t = static_cast<double>(k) / n;
      return t * t * (3 - 2 * t) * 0.5 + 0.5 * t * t;
    };
    for (int i = 0; i < nu; ++i) {
      for (int j = 0; j < nv; ++j) {
        const double u0 = cut(i, nu), u1 = cut(i + 1, nu), v0 = cut(j, nv), v1 = cut(j + 1, nv);
        polygons.push_back(quad(corner + u0 * u + v0 * v, (u1 - u0) * u, (v1 - v0) * v));
      }
    }
  }
  return polygons;
}

TEST(PatchFormFactor, BoxFacesCloseToOne) {
  double worst = 0.0;
  for (bool split : {false, true}) {
    for (const dvec3& size : {dvec3(1, 1, 1), dvec3(1, 2, 3), dvec3(0.1, 1, 5)}) {
      const auto polygons = box_faces(size, split);
      for (const Polygon& p : polygons) {
        double sum = 0.0;
        for (const Polygon& q : polygons) sum += patch_form_factor(p, q);
        EXPECT_NEAR(sum, 1.0, 1e-8) << "split " << split << " size " << size.y << " " << size.z;
        worst = std::max(worst, std::abs(sum - 1.0));
      }
    }
  }
  std::printf("box closure: worst |sum - 1| %.2e\n", worst);
}

// --- Invariance ------------------------------------------------------------------

Polygon transformed(const Polygon& polygon, const glm::dmat4& m) {
  Polygon out;
  for (const dvec3& v : polygon) out.push_back(dvec3(m * glm::dvec4(v, 1.0)));
  return out;
}

TEST(PatchFormFactor, InvariantUnderTranslationRotationScale) {
  const glm::dmat4 identity(1.0);
  const std::array<glm::dmat4, 5> transforms = {
      glm::translate(identity, dvec3(1e6, -1e6, 1e6)),
      glm::rotate(identity, 1.234, glm::normalize(dvec3(0.3, -1, 2))),
      glm::scale(identity, dvec3(1e-6)),
      glm::scale(identity, dvec3(1e6)),
      glm::scale(glm::rotate(identity, -2.2, glm::normalize(dvec3(1, 1, 0.1))), dvec3(3e-6)),
  };
  double worst = 0.0;
  int index = 0;
  for (const Pair& pair : random_pairs(3, 120)) {
    ++index;
    for (size_t t = 0; t < transforms.size(); ++t) {
      const glm::dmat4& m = transforms[t];
      const Polygon p = transformed(pair.p, m), q = transformed(pair.q, m);
      const double moved = patch_form_factor(p, q);
      // The offset rounds the input itself (1e-10 at 1e6), which moves a
      // straddling sliver's F by more than 1e-9: compare with the same rounded
      // geometry moved back, exactly.
      const glm::dmat4 back = t == 0 ? glm::inverse(m) : identity;
      const double reference = t == 0
                                   ? patch_form_factor(transformed(p, back), transformed(q, back))
                                   : patch_form_factor(pair.p, pair.q);
      if (reference == 0.0) {
        EXPECT_LT(moved, 1e-12);
        continue;
      }
      const double error = relative_error(moved, reference);
      EXPECT_LT(error, 1e-9) << "pair " << index << " transform " << t << " F " << reference;
      worst = std::max(worst, error);
    }
  }
  std::printf("invariance: worst relative error %.2e\n", worst);
}

// --- Degenerate and extreme configurations -------------------------------------------

TEST(PatchFormFactor, NothingFacingIsZero) {
  const Polygon floor = floor_rectangle(0, 1, 0, 1);
  // Coplanar: side by side, overlapping, and facing opposite ways.
  EXPECT_EQ(patch_form_factor(floor, floor_rectangle(1, 2, 0, 1)), 0.0);
  EXPECT_EQ(patch_form_factor(floor, floor_rectangle(0.5, 1.5, 0.2, 0.7)), 0.0);
  EXPECT_EQ(patch_form_factor(floor, test::rectangle_facing_down(1, 2, 0, 1, 0)), 0.0);
  EXPECT_EQ(patch_form_factor(floor, floor), 0.0);
  // Back to back; parallel but facing the same way; wholly behind.
  EXPECT_EQ(patch_form_factor(floor, test::rectangle_facing_down(0, 1, 0, 1, -1)), 0.0);
  EXPECT_EQ(patch_form_factor(floor, floor_rectangle(0, 1, 0, 1)), 0.0);
  EXPECT_EQ(patch_form_factor(test::rectangle_facing_down(0, 1, 0, 1, 0), floor), 0.0);
  const Polygon above = floor_rectangle(0, 1, 0, 1);
  EXPECT_EQ(
      patch_form_factor(floor, transformed(above, glm::translate(glm::dmat4(1.0), dvec3(0, 0, 1)))),
      0.0);
  const Polygon wall_behind = quad({0, 0, -2}, {0, 1, 0}, {0, 0, 1});
  EXPECT_EQ(patch_form_factor(floor, wall_behind), 0.0);
  EXPECT_EQ(patch_form_factor(wall_behind, floor), 0.0);
  // A wall on the floor's edge facing away from it.
  const Polygon away = quad({0, 0, 0}, {0, 0, 1}, {0, 1, 0});
  EXPECT_EQ(patch_form_factor(floor, away), 0.0);
  EXPECT_EQ(patch_form_factor(away, floor), 0.0);
  // Degenerate input.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(patch_form_factor(floor, Polygon{{0, 0, 1}, {1, 0, 1}, {2, 0, 1}}), 0.0);
  EXPECT_EQ(patch_form_factor(floor, Polygon{{0, 0, 1}, {1, 0, nan}, {0, 1, 1}}), 0.0);
  EXPECT_EQ(patch_form_factor(floor, Polygon{{0, 0, 1}, {1, 0, 1}}), 0.0);
}

TEST(PatchFormFactor, StraddlingCountsOnlyTheFacingParts) {
  // A wall crossing the floor's plane counts as its upper half, and the floor
  // as its part in front of the wall.
  const Polygon floor = floor_rectangle(-1, 1, 0, 1);
  const Polygon wall = quad({0, 0, -1}, {0, 1, 0}, {0, 0, 2});  // x = 0, facing +x
  const double expected = perpendicular_rectangles(1, 1, 1);
  EXPECT_LT(relative_error(patch_form_factor(floor, wall), 0.5 * expected), 1e-8);
  EXPECT_LT(relative_error(patch_form_factor(wall, floor), 0.5 * expected), 1e-8);
}

TEST(PatchFormFactor, TinyAndHugeDistances) {
  const Polygon p = floor_rectangle(-0.5, 0.5, -0.5, 0.5);
  for (double c : {1e-9, 1e-6, 1e-3}) {
    const Polygon q = test::rectangle_facing_down(-0.5, 0.5, -0.5, 0.5, c);
    EXPECT_LT(relative_error(patch_form_factor(p, q), parallel_rectangles(1, 1, c)), 1e-8) << c;
  }
  for (double c : {1e3, 1e5, 1e9}) {
    // Far field, where the closed form cancels: its expansion in 1 / c (checked
    // against it evaluated in 50 digits).
    const Polygon q = test::rectangle_facing_down(-0.5, 0.5, -0.5, 0.5, c);
    const double expected = (1 - 2 / (3 * c * c)) / (kPi * c * c);  // + O(1 / c^6)
    EXPECT_LT(relative_error(patch_form_factor(p, q), expected), 1e-8) << c;
  }
  // A tiny patch far from a big one, and the other way round.
  const Polygon tiny = test::rectangle_facing_down(-0.5e-9, 0.5e-9, -0.5e-9, 0.5e-9, 1);
  const double f = patch_form_factor(tiny, p);
  EXPECT_LT(relative_error(f, form_factor(dvec3(0, 0, 1), dvec3(0, 0, -1), p)), 1e-6);
  EXPECT_LT(relative_error(patch_form_factor(p, tiny), f * 1e-18), 1e-6);
}

// Found by the fuzz slice (scene seed 4): next to a face 1e-12 of its size, the
// integrand's own rounding exceeds the quadrature's tolerance, and the adaptive
// Gauss-Kronrod split every interval down to depth 40 (2^40 of them: the solve
// never returned). The subdivisions are now bounded.
TEST(PatchFormFactor, NeighbourOneTrillionthTheSizeReturns) {
  const Polygon quad_p = {
      {-4.721087714336642e-10, -4.2729275236462975e-09, -4.9719602538841866e-11},
      {5.020433486652835e-09, -3.2097653727151637e-09, -3.2096664895593493e-09},
      {4.3486241962839191e-09, -2.111938573966085e-09, -4.0080257994517912e-09},
      {-3.8029735139882818e-09, 1.1701537641651122e-09, -4.0080257994517904e-09}};
  const Polygon tiny = {
      {-2.5779088494727169e-09, -2.3716603553894362e-11, -2.4121532306288478e-09},
      {-2.5779088494722595e-09, -2.3716603554321239e-11, -2.4121532306303872e-09},
      {-2.5779088494707292e-09, -2.3716603554665055e-11, -2.4121532306298371e-09},
      {-2.5779088494711866e-09, -2.3716603554238178e-11, -2.4121532306282978e-09}};
  // Returning at all is the test (a hang fails it at ctest's --timeout; no
  // wall-clock bound here, which a loaded machine could break).
  const double f = patch_form_factor(quad_p, tiny);
  const double back = patch_form_factor(tiny, quad_p);
  EXPECT_TRUE(std::isfinite(f));
  EXPECT_TRUE(std::isfinite(back));
  // What reaches a face 1e-24 of the quad's area is nothing at double precision.
  EXPECT_GE(f, 0.0);
  EXPECT_LT(f, 1e-12);
  EXPECT_GE(back, 0.0);
  EXPECT_LE(back, 1.0);
}

// A small square wall standing on the middle of a large floor, down to 1e-10
// of its size: it sees the floor below its horizon, 1/2 less what lies
// beyond the floor's edges (of order s / L). The contour form alone loses
// digits in proportion to the sizes' ratio (fuzzing: F = 3.5e12 for a
// 1.5e-14 polygon on a 0.25 one; here 21 s / L off at 1e-10, and reciprocity
// broken from 1e-6).
TEST(PatchFormFactor, SmallWallOnALargeFloorAtAnyRatio) {
  const double half = 0.125;
  const Polygon floor = floor_rectangle(-half, half, -half, half);
  double worst = 0.0;
  for (double s : {1e-2, 1e-4, 1e-6, 1e-8, 1e-10}) {
    const Polygon wall = quad({0, -0.5 * s, 0}, {0, s, 0}, {0, 0, s});  // x = 0, facing +x
    const double f = patch_form_factor(wall, floor);
    worst = std::max(worst, std::abs(f - 0.5) / (s / half));
    EXPECT_LE(f, 0.5 + 1e-9) << s;
    EXPECT_NEAR(f, 0.5, 2.0 * s / half + 1e-9) << s;
    EXPECT_NEAR(patch_form_factor(floor, wall) * area(floor), f * area(wall), 1e-9 * f * area(wall))
        << s;
  }
  std::printf("small wall on a large floor: |F - 1/2| <= %.2f s / L\n", worst);
}

}  // namespace
}  // namespace radiosity
