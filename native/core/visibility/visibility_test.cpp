// Tests of occlusion (Section 4.3): the exact visible polygon, its form factor and
// gradient, the sampled mode, and shaft culling. References are independent of
// the code under test: MATH.md values, Monte Carlo integration with a ray caster
// written here, central finite differences, brute force.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/visibility/ray_scene.h"
#include "core/visibility/sampled_visibility.h"
#include "core/visibility/visible_polygon.h"

namespace radiosity {
namespace {

using Polygon = std::vector<dvec3>;

// Emitter of MATH.md section 5: the square [-1/2, 1/2]^2 at z = 2 facing down
// (counter-clockwise about -z).
Polygon math_emitter() {
  return {{-0.5, -0.5, 2.0}, {-0.5, 0.5, 2.0}, {0.5, 0.5, 2.0}, {0.5, -0.5, 2.0}};
}

Triangle math_occluder() {
  return {{dvec3(0.10, 0.05, 1.00), dvec3(0.45, -0.10, 0.90), dvec3(0.40, 0.20, 1.15)}};
}

struct MonteCarlo {
  double mean = 0.0;
  double standard_error = 0.0;
};

// F of the visible part by uniform area sampling of the emitter: the estimator
// A cos_r cos_e / (pi d^2) * visibility, averaged.
MonteCarlo monte_carlo_form_factor(const dvec3& r, const dvec3& n, const Polygon& emitter,
                                   const std::vector<Triangle>& occluders, int samples,
                                   std::mt19937_64& rng) {
  std::vector<double> cumulative;
  double area = 0.0;
  dvec3 ne(0.0);
  for (std::size_t i = 1; i + 1 < emitter.size(); ++i) {
    const dvec3 c = glm::cross(emitter[i] - emitter[0], emitter[i + 1] - emitter[0]);
    ne += c;
    area += 0.5 * glm::length(c);
    cumulative.push_back(area);
  }
  ne = glm::normalize(ne);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  double sum = 0.0, sum2 = 0.0;
  for (int k = 0; k < samples; ++k) {
    const double pick = uni(rng) * area;
    std::size_t tri = 0;
    while (tri + 1 < cumulative.size() && cumulative[tri] < pick) ++tri;
    double a = uni(rng), b = uni(rng);
    if (a + b > 1.0) {
      a = 1.0 - a;
      b = 1.0 - b;
    }
    const dvec3 y =
        emitter[0] + a * (emitter[tri + 1] - emitter[0]) + b * (emitter[tri + 2] - emitter[0]);
    const dvec3 d = y - r;
    const double d2 = glm::dot(d, d);
    const double cr = glm::dot(n, d), ce = -glm::dot(ne, d);
    double value = 0.0;
    if (cr > 0.0 && ce > 0.0) {
      bool blocked = false;
      for (const Triangle& t : occluders)
        if (segment_hits_triangle(r, y, t)) {
          blocked = true;
          break;
        }
      if (!blocked) value = area * cr * ce / (kPi * d2 * d2);
    }
    sum += value;
    sum2 += value * value;
  }
  MonteCarlo mc;
  mc.mean = sum / samples;
  mc.standard_error = std::sqrt(std::max(0.0, sum2 / samples - mc.mean * mc.mean) / samples);
  return mc;
}

// A random configuration: a convex emitter (triangle or quad) around z = 2, tilted,
// facing down; a receiver point near z = 0 with a normal facing up; occluders
// between them.
struct Configuration {
  Polygon emitter;
  dvec3 r{0.0}, n{0.0, 0.0, 1.0};
  std::vector<Triangle> occluders;
};

dvec3 random_in_ball(std::mt19937_64& rng, double radius) {
  std::uniform_real_distribution<double> uni(-1.0, 1.0);
  for (;;) {
    const dvec3 p(uni(rng), uni(rng), uni(rng));
    if (glm::dot(p, p) <= 1.0) return radius * p;
  }
}

Configuration random_configuration(std::mt19937_64& rng, int occluder_count, double occluder_size) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  Configuration c;
  const int sides = uni(rng) < 0.5 ? 3 : 4;
  // Points on an ellipse, counter-clockwise about +z, then reversed to face down.
  const double a = 0.5 + uni(rng), b = 0.5 + uni(rng), phase = 2.0 * kPi * uni(rng);
  for (int i = 0; i < sides; ++i) {
    const double t = phase + 2.0 * kPi * (i + 0.3 * uni(rng)) / sides;
    c.emitter.push_back({a * std::cos(t), b * std::sin(t), 0.0});
  }
  std::reverse(c.emitter.begin(), c.emitter.end());
  // Tilt about a random horizontal axis, then lift.
  const double tilt = 0.4 * (uni(rng) - 0.5), axis = 2.0 * kPi * uni(rng);
  const dvec3 k(std::cos(axis), std::sin(axis), 0.0);
  const dvec3 offset(0.2 * (uni(rng) - 0.5), 0.2 * (uni(rng) - 0.5), 2.0);
  for (dvec3& v : c.emitter) {
    v = v * std::cos(tilt) + glm::cross(k, v) * std::sin(tilt) +
        k * glm::dot(k, v) * (1.0 - std::cos(tilt)) + offset;
  }
  c.r = dvec3(0.6 * (uni(rng) - 0.5), 0.6 * (uni(rng) - 0.5), 0.0);
  c.n = glm::normalize(dvec3(0.0, 0.0, 1.0) + random_in_ball(rng, 0.5));
  for (int i = 0; i < occluder_count; ++i) {
    // Centres on the segment to a random emitter point, so they do occlude.
    const dvec3 target = dvec3(0.5 * (uni(rng) - 0.5), 0.5 * (uni(rng) - 0.5), 2.0);
    const dvec3 centre = c.r + (0.25 + 0.5 * uni(rng)) * (target - c.r);
    Triangle t;
    for (dvec3& v : t.v) v = centre + random_in_ball(rng, occluder_size);
    c.occluders.push_back(t);
  }
  return c;
}

double visible_f(const dvec3& r, const dvec3& n, const Polygon& emitter,
                 const std::vector<Triangle>& occluders) {
  return visible_form_factor_gradient(r, n, emitter, occluders).value;
}

// --- Exact visible polygon ------------------------------------------------------------

TEST(VisiblePolygon, MathOcclusionCase) {
  const dvec3 r(0.03, -0.02, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
  const Polygon emitter = math_emitter();
  const std::vector<Triangle> occluders{math_occluder()};
  EXPECT_NEAR(form_factor(r, n, emitter), 0.071435392606715, 1e-14);
  const FormFactorGradient fg = visible_form_factor_gradient(r, n, emitter, occluders);
  EXPECT_NEAR(fg.value, 0.067975166508788, 1e-14);
  // MATH.md gives the gradient to 8 digits from finite differences.
  EXPECT_NEAR(fg.gradient.x, -0.02685189, 1e-8);
  EXPECT_NEAR(fg.gradient.y, 0.00306648, 1e-8);
  EXPECT_NEAR(fg.gradient.z, 0.06437021, 1e-8);
  // Only the first occluder vertex projects inside the emitter (the other two
  // land beyond x = 1/2): one intrinsic vertex anchored at its 3D position, and
  // apparent vertices where occluder edges cross the emitter's edges.
  const VisiblePolygon visible = visible_polygon(r, n, emitter, occluders);
  EXPECT_TRUE(visible.occluded);
  int anchored = 0, apparent = 0;
  for (const VisiblePiece& piece : visible.pieces)
    for (const ContourVertex& v : piece) {
      if (v.apparent) ++apparent;
      if (!v.apparent && glm::length(v.anchor - occluders[0].v[0]) < 1e-12) ++anchored;
    }
  EXPECT_GE(anchored, 1);
  EXPECT_GE(apparent, 2);
}

TEST(VisiblePolygon, NoOccluderIsTheUnoccludedFormFactor) {
  std::mt19937_64 rng(1);
  for (int i = 0; i < 20; ++i) {
    const Configuration c = random_configuration(rng, 0, 0.0);
    const FormFactorGradient exact = form_factor_gradient(c.r, c.n, c.emitter);
    const FormFactorGradient visible = visible_form_factor_gradient(c.r, c.n, c.emitter, {});
    EXPECT_EQ(visible.value, exact.value);
    EXPECT_EQ(visible.gradient, exact.gradient);
  }
}

TEST(VisiblePolygon, ExactMatchesMonteCarlo) {
  std::mt19937_64 rng(7);
  double worst_sigmas = 0.0;
  for (int i = 0; i < 24; ++i) {
    const Configuration c = random_configuration(rng, 1 + i % 6, 0.25);
    const double exact = visible_f(c.r, c.n, c.emitter, c.occluders);
    const MonteCarlo mc = monte_carlo_form_factor(c.r, c.n, c.emitter, c.occluders, 200000, rng);
    const double sigmas = std::abs(exact - mc.mean) / (mc.standard_error + 1e-300);
    worst_sigmas = std::max(worst_sigmas, sigmas);
    EXPECT_LT(sigmas, 4.5) << "configuration " << i << ": exact " << exact << " mc " << mc.mean
                           << " +- " << mc.standard_error;
    // The occluders do occlude: the test would not notice an ignored occluder otherwise.
    if (i < 6) {
      EXPECT_LT(exact, form_factor(c.r, c.n, c.emitter));
    }
  }
  RecordProperty("worst_sigmas", std::to_string(worst_sigmas));
  std::printf("exact vs Monte Carlo: worst deviation %.2f standard errors\n", worst_sigmas);
}

// The value-only path (no vertex generators, no gradient) walks the same
// visible pieces: the same F to rounding, occluded or not, hidden or not.
TEST(VisiblePolygon, FormFactorAloneEqualsTheGradientPathsValue) {
  std::mt19937_64 rng(11);
  int occluded = 0, hidden = 0;
  for (int i = 0; i < 300; ++i) {
    const Configuration c = random_configuration(rng, i % 7, i % 2 ? 0.25 : 0.8);
    const double with_gradient = visible_f(c.r, c.n, c.emitter, c.occluders);
    const double alone = visible_form_factor(c.r, c.n, c.emitter, c.occluders);
    const double open = form_factor(c.r, c.n, c.emitter);
    EXPECT_NEAR(alone, with_gradient, 1e-12 * open) << "configuration " << i;
    // Both report the unoccluded F they bound themselves by, hidden or not.
    double open_alone = -1.0, open_with_gradient = -1.0;
    EXPECT_EQ(visible_form_factor(c.r, c.n, c.emitter, c.occluders, &open_alone), alone);
    visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders, &open_with_gradient);
    EXPECT_EQ(open_alone, open) << "configuration " << i;
    EXPECT_NEAR(open_with_gradient, open, 1e-14 * open) << "configuration " << i;
    occluded += with_gradient < open * (1.0 - 1e-9) ? 1 : 0;
    hidden += with_gradient == 0.0 ? 1 : 0;
  }
  // The configurations cover partly and wholly hidden emitters.
  EXPECT_GT(occluded, 100);
  EXPECT_GT(hidden, 0);
}

// Central differences of the exact occluded F at the receiver point, at steps h
// and h/2, extrapolated (Richardson: the two differ by 3/4 of the coarse one's
// h^2 error). `smooth` where they agree: no discontinuity within the stencil,
// so a gradient can be checked against them there.
struct FiniteDifference {
  dvec3 gradient;
  double scale;  // the gradient's size, at least 1e-3: what errors are relative to
  bool smooth;
};

FiniteDifference finite_difference(const Configuration& c) {
  const double h = 2e-5;  // about 1e-5 of the scene: truncation and rounding both below 1e-8
  dvec3 fd(0.0), fd_half(0.0);
  for (int k = 0; k < 3; ++k) {
    dvec3 e(0.0);
    e[k] = 1.0;
    fd[k] = (visible_f(c.r + h * e, c.n, c.emitter, c.occluders) -
             visible_f(c.r - h * e, c.n, c.emitter, c.occluders)) /
            (2.0 * h);
    fd_half[k] = (visible_f(c.r + 0.5 * h * e, c.n, c.emitter, c.occluders) -
                  visible_f(c.r - 0.5 * h * e, c.n, c.emitter, c.occluders)) /
                 h;
  }
  const dvec3 richardson = (4.0 * fd_half - fd) / 3.0;
  const double scale = std::max(glm::length(richardson), 1e-3);
  return {richardson, scale, glm::length(fd - fd_half) <= 1e-5 * scale};
}

// The analytic gradient of configuration `i` against finite differences,
// where the visible form factor is positive and smooth there.
struct GradientCheck {
  int tested = 0, skipped = 0;
  double worst = 0.0;

  void operator()(const Configuration& c, int i) {
    const FormFactorGradient fg = visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders);
    if (fg.value <= 0.0) return;
    const FiniteDifference fd = finite_difference(c);
    if (!fd.smooth) {
      ++skipped;
      return;
    }
    ++tested;
    const double error = glm::length(fg.gradient - fd.gradient) / fd.scale;
    worst = std::max(worst, error);
    EXPECT_LT(error, 1e-5) << "configuration " << i << " gradient (" << fg.gradient.x << ", "
                           << fg.gradient.y << ", " << fg.gradient.z << ") fd (" << fd.gradient.x
                           << ", " << fd.gradient.y << ", " << fd.gradient.z << ")";
  }
};

// The gradient against finite_difference where it is smooth.
TEST(VisiblePolygon, GradientMatchesFiniteDifferences) {
  std::mt19937_64 rng(11);
  GradientCheck check;
  for (int i = 0; i < 200; ++i) check(random_configuration(rng, 2 + i % 4, 0.3), i);
  std::printf("gradient vs finite differences: %d tested, %d skipped, worst relative error %.3g\n",
              check.tested, check.skipped, check.worst);
  EXPECT_GE(check.tested, 150);
  EXPECT_LE(check.skipped, check.tested / 10);
}

// --- Degenerate configurations ------------------------------------------------------

// Finite, F in [0, unoccluded], and (when `samples` > 0) within 4.5 standard errors
// of Monte Carlo.
void expect_sane(const dvec3& r, const dvec3& n, const Polygon& emitter,
                 const std::vector<Triangle>& occluders, int samples, const char* what) {
  const FormFactorGradient fg = visible_form_factor_gradient(r, n, emitter, occluders);
  const double unoccluded = form_factor(r, n, emitter);
  EXPECT_TRUE(std::isfinite(fg.value) && std::isfinite(fg.gradient.x) &&
              std::isfinite(fg.gradient.y) && std::isfinite(fg.gradient.z))
      << what;
  EXPECT_GE(fg.value, 0.0) << what;
  EXPECT_LE(fg.value, unoccluded) << what;
  if (samples > 0) {
    std::mt19937_64 rng(3);
    const MonteCarlo mc = monte_carlo_form_factor(r, n, emitter, occluders, samples, rng);
    EXPECT_LT(std::abs(fg.value - mc.mean), 4.5 * mc.standard_error + 1e-12)
        << what << ": exact " << fg.value << " mc " << mc.mean << " +- " << mc.standard_error;
  }
}

// Two triangles of the quad a, b, c, d.
std::vector<Triangle> quad(const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& d) {
  return {Triangle{{a, b, c}}, Triangle{{a, c, d}}};
}

// The 12 triangles of an axis-aligned box, front and back faces all given.
std::vector<Triangle> box(const dvec3& lo, const dvec3& hi) {
  const auto corner = [&](int i) {
    return dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
  };
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                           {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
  std::vector<Triangle> out;
  for (const auto& f : faces) {
    const auto q = quad(corner(f[0]), corner(f[1]), corner(f[2]), corner(f[3]));
    out.insert(out.end(), q.begin(), q.end());
  }
  return out;
}

// The same with the structures that make the other vertex kinds: occluders
// piercing the emitter plane (traces, intrinsic piercing points), closed boxes
// (shared vertices, parallel edges), and receiver normals tilted so far that the
// horizon cuts the emitter (fixed horizon vertices).
TEST(VisiblePolygon, GradientMatchesFiniteDifferencesWithTracesBoxesAndHorizon) {
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  GradientCheck check;
  for (int i = 0; i < 150; ++i) {
    Configuration c = random_configuration(rng, 1, 0.3);
    c.n = glm::normalize(dvec3(0.0, 0.0, 1.0) + random_in_ball(rng, 1.2));
    if (c.n.z < 0.2) c.n.z = 0.2;
    c.n = glm::normalize(c.n);
    const dvec3 centre(0.6 * (uni(rng) - 0.5), 0.6 * (uni(rng) - 0.5), 2.0);
    c.occluders.push_back(
        Triangle{{centre + dvec3(-0.3, -0.2, -0.4), centre + dvec3(0.3, -0.1, 0.4),
                  centre + random_in_ball(rng, 0.3) - dvec3(0.0, 0.0, 0.3)}});
    const dvec3 lo = c.r + (0.3 + 0.4 * uni(rng)) * (centre - c.r) - dvec3(0.1, 0.1, 0.1);
    for (const Triangle& t : box(lo, lo + dvec3(0.1 + 0.2 * uni(rng), 0.1 + 0.2 * uni(rng), 0.2)))
      c.occluders.push_back(t);
    check(c, i);
  }
  std::printf(
      "gradient vs finite differences (traces, boxes, horizon): %d tested, %d skipped, "
      "worst relative error %.3g\n",
      check.tested, check.skipped, check.worst);
  EXPECT_GE(check.tested, 100);
  EXPECT_LE(check.skipped, check.tested / 10);
}

// The four children of a polygon as the hierarchy makes them: a quad through
// its edge midpoints and centre, a triangle through its edge midpoints.
std::vector<Polygon> children_of(const Polygon& p) {
  const auto mid = [&](size_t i, size_t j) { return 0.5 * (p[i] + p[j]); };
  if (p.size() == 3) {
    return {{p[0], mid(0, 1), mid(2, 0)},
            {mid(0, 1), p[1], mid(1, 2)},
            {mid(2, 0), mid(1, 2), p[2]},
            {mid(0, 1), mid(1, 2), mid(2, 0)}};
  }
  const dvec3 c = 0.25 * (p[0] + p[1] + p[2] + p[3]);
  return {{p[0], mid(0, 1), c, mid(3, 0)},
          {mid(0, 1), p[1], mid(1, 2), c},
          {c, mid(1, 2), p[2], mid(2, 3)},
          {mid(3, 0), c, mid(2, 3), p[3]}};
}

TEST(VisiblePolygon, PartsOfASplitEmitterMatchOneCallPerPart) {
  std::mt19937_64 rng(31);
  int occluded = 0;
  double worst_value = 0.0, worst_gradient = 0.0;
  for (int i = 0; i < 300; ++i) {
    Configuration c = random_configuration(rng, 1 + i % 6, 0.25);
    // Every third receiver leans over so the horizon cuts the emitter.
    if (i % 3 == 0) c.n = glm::normalize(dvec3(1.5, 0.3, 1.0));
    const std::vector<Polygon> children = children_of(c.emitter);
    std::vector<std::span<const dvec3>> parts(children.begin(), children.end());
    std::vector<FormFactorGradient> together(children.size());
    std::vector<double> open(children.size(), -1.0);
    visible_form_factor_gradient_parts(c.r, c.n, c.emitter, parts, c.occluders, together, open);
    const FormFactorGradient whole = visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders);
    const double scale = std::max(whole.value, 1e-3);
    double sum = 0.0;
    for (size_t k = 0; k < children.size(); ++k) {
      const FormFactorGradient alone =
          visible_form_factor_gradient(c.r, c.n, children[k], c.occluders);
      const double gradient_scale =
          std::max(glm::length(alone.gradient), glm::length(whole.gradient)) + 1e-3;
      worst_value = std::max(worst_value, std::abs(together[k].value - alone.value) / scale);
      worst_gradient = std::max(
          worst_gradient, glm::length(together[k].gradient - alone.gradient) / gradient_scale);
      EXPECT_NEAR(together[k].value, alone.value, 1e-10 * scale)
          << "configuration " << i << " part " << k;
      const double part_open = form_factor(c.r, c.n, children[k]);
      EXPECT_NEAR(open[k], part_open, 1e-14 * std::max(part_open, 1e-3))
          << "configuration " << i << " part " << k;
      EXPECT_LT(glm::length(together[k].gradient - alone.gradient), 1e-8 * gradient_scale)
          << "configuration " << i << " part " << k;
      sum += together[k].value;
    }
    EXPECT_NEAR(sum, whole.value, 1e-10 * scale) << "configuration " << i;
    occluded += whole.value < form_factor(c.r, c.n, c.emitter) * (1.0 - 1e-9) ? 1 : 0;
  }
  std::printf(
      "split emitter: worst value error %.3g, worst gradient error %.3g, %d of 300 occluded\n",
      worst_value, worst_gradient, occluded);
  EXPECT_GE(occluded, 150);
}

TEST(VisiblePolygon, AlignedOccluderHidesExactlyHalf) {
  // Projection of the occluder from the centre covers exactly the right half of the
  // emitter: its edges lie on the emitter's edges (D1 events), and the halves have
  // equal F by symmetry.
  const dvec3 r(0.0), n(0.0, 0.0, 1.0);
  const Polygon emitter = math_emitter();
  const auto occluder =
      quad({0.0, -0.25, 1.0}, {0.25, -0.25, 1.0}, {0.25, 0.25, 1.0}, {0.0, 0.25, 1.0});
  const FormFactorGradient fg = visible_form_factor_gradient(r, n, emitter, occluder);
  const FormFactorGradient half = form_factor_gradient(
      r, n, Polygon{{-0.5, -0.5, 2.0}, {-0.5, 0.5, 2.0}, {0.0, 0.5, 2.0}, {0.0, -0.5, 2.0}});
  EXPECT_NEAR(fg.value, 0.5 * form_factor(r, n, emitter), 1e-15);
  EXPECT_NEAR(fg.value, half.value, 1e-15);
  EXPECT_TRUE(std::isfinite(glm::length(fg.gradient)));
  // Same with the occluder split in two along x = 1/8 and given twice (a closed,
  // flat mesh): the shared edge and the duplicate change nothing.
  auto split = quad({0.0, -0.25, 1.0}, {0.125, -0.25, 1.0}, {0.125, 0.25, 1.0}, {0.0, 0.25, 1.0});
  const auto right =
      quad({0.125, -0.25, 1.0}, {0.25, -0.25, 1.0}, {0.25, 0.25, 1.0}, {0.125, 0.25, 1.0});
  split.insert(split.end(), right.begin(), right.end());
  split.insert(split.end(), occluder.begin(), occluder.end());
  EXPECT_NEAR(visible_f(r, n, emitter, split), half.value, 1e-15);
}

TEST(VisiblePolygon, OccluderCrossingTheEmitterPlaneIsClippedThere) {
  // A triangle reaching behind the emitter occludes like its part in front.
  const dvec3 r(0.1, 0.05, 0.0), n(0.0, 0.0, 1.0);
  const Polygon emitter = math_emitter();
  const Triangle through{{dvec3(-0.2, -0.1, 1.5), dvec3(0.3, -0.1, 2.5), dvec3(0.0, 0.3, 1.5)}};
  // Its part with z <= 2: the quad (-0.2,-0.1,1.5), (0.05,-0.1,2), (0.15,0.1,2), (0,0.3,1.5).
  const auto front = quad({-0.2, -0.1, 1.5}, {0.05, -0.1, 2.0}, {0.15, 0.1, 2.0}, {0.0, 0.3, 1.5});
  const FormFactorGradient a =
      visible_form_factor_gradient(r, n, emitter, std::vector<Triangle>{through});
  const FormFactorGradient b = visible_form_factor_gradient(r, n, emitter, front);
  EXPECT_NEAR(a.value, b.value, 1e-14);
  EXPECT_NEAR(glm::length(a.gradient - b.gradient), 0.0, 1e-12);
  EXPECT_LT(a.value, form_factor(r, n, emitter));
  expect_sane(r, n, emitter, {through}, 200000, "crossing the emitter plane");
}

TEST(VisiblePolygon, DegenerateConfigurations) {
  const dvec3 r(0.03, -0.02, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
  const Polygon emitter = math_emitter();
  const double unoccluded = form_factor(r, n, emitter);

  // Touching the emitter: an edge lying on the emitter, inside it.
  expect_sane(r, n, emitter,
              {Triangle{{dvec3(-0.3, 0.0, 2.0), dvec3(0.2, 0.1, 2.0), dvec3(0.0, 0.0, 1.4)}}},
              200000, "edge on the emitter");
  // Touching the emitter at a vertex only, and along the emitter's own edge.
  expect_sane(r, n, emitter,
              {Triangle{{dvec3(0.0, 0.0, 2.0), dvec3(0.3, 0.1, 1.5), dvec3(-0.1, 0.3, 1.6)}}},
              200000, "vertex on the emitter");
  expect_sane(r, n, emitter,
              {Triangle{{dvec3(-0.5, -0.5, 2.0), dvec3(0.5, -0.5, 2.0), dvec3(0.0, 0.0, 1.5)}}},
              200000, "edge on the emitter's edge");
  // Touching the receiver: a vertex at r, an edge through r (planes holding r
  // project to segments and hide nothing of positive measure).
  expect_sane(r, n, emitter, {Triangle{{r, dvec3(0.2, 0.1, 1.0), dvec3(0.0, 0.3, 1.2)}}}, 200000,
              "vertex at the receiver");
  EXPECT_NEAR(
      visible_f(r, n, emitter,
                {Triangle{{r - dvec3(0.5, 0, 0), r + dvec3(0.5, 0, 0), dvec3(0.0, 0.1, 1.5)}}}),
      unoccluded, 1e-15);
  // A triangle near the receiver, reaching below and behind it.
  expect_sane(r, n, emitter,
              {Triangle{{dvec3(-0.5, -0.4, -0.3), dvec3(0.3, 0.6, -0.3), dvec3(0.1, 0.0, 0.2)}}},
              200000, "through the receiver's plane");
  // Coplanar with the emitter (a neighbour or an overlapping face): hides nothing.
  EXPECT_EQ(visible_f(r, n, emitter, quad({-1, -1, 2}, {1, -1, 2}, {1, 1, 2}, {-1, 1, 2})),
            unoccluded);
  // Coplanar with the receiver's tangent plane, and holding r.
  EXPECT_NEAR(
      visible_f(r, n, emitter,
                {Triangle{{r + dvec3(1, 0, -0.1), r + dvec3(-1, 1, 0.2), r + dvec3(-1, -1, 0.0)}}}),
      unoccluded, 1e-15);
  // Behind the emitter, behind the receiver: nothing.
  EXPECT_EQ(visible_f(r, n, emitter, quad({-1, -1, 2.5}, {1, -1, 2.5}, {1, 1, 2.5}, {-1, 1, 2.5})),
            unoccluded);
  EXPECT_EQ(
      visible_f(r, n, emitter, quad({-1, -1, -0.5}, {1, -1, -0.5}, {1, 1, -0.5}, {-1, 1, -0.5})),
      unoccluded);
  // A floor-to-ceiling blocker larger than the pyramid: all hidden.
  const auto wall = quad({-5, -5, 1}, {5, -5, 1}, {5, 5, 1}, {-5, 5, 1});
  const FormFactorGradient hidden = visible_form_factor_gradient(r, n, emitter, wall);
  EXPECT_EQ(hidden.value, 0.0);
  EXPECT_EQ(hidden.gradient, dvec3(0.0));
  // A tiny occluder changes almost nothing and stays finite.
  const double tiny =
      visible_f(r, n, emitter, {Triangle{{dvec3(0, 0, 1), dvec3(1e-9, 0, 1), dvec3(0, 1e-9, 1)}}});
  EXPECT_LE(tiny, unoccluded);
  EXPECT_NEAR(tiny, unoccluded, 1e-15);
  // Closed meshes, front and back faces: a box in the way, boxes overlapping.
  expect_sane(r, n, emitter, box({0.0, -0.1, 0.8}, {0.3, 0.2, 1.2}), 200000, "box");
  std::vector<Triangle> boxes = box({0.0, -0.1, 0.8}, {0.3, 0.2, 1.2});
  for (const Triangle& t : box({-0.2, 0.0, 1.0}, {0.1, 0.3, 1.5})) boxes.push_back(t);
  for (const Triangle& t : box({-0.1, -0.3, 0.5}, {0.2, 0.0, 0.9})) boxes.push_back(t);
  expect_sane(r, n, emitter, boxes, 200000, "three overlapping boxes");
  // A box that covers the whole pyramid: nothing visible.
  EXPECT_EQ(visible_f(r, n, emitter, box({-2, -2, 0.5}, {2, 2, 1.5})), 0.0);
  // Receiver on the emitter plane and behind it.
  EXPECT_EQ(visible_f(dvec3(0.1, 0.1, 2.0), n, emitter, {math_occluder()}), 0.0);
  EXPECT_EQ(visible_f(dvec3(0.1, 0.1, 3.0), n, emitter, {math_occluder()}), 0.0);
}

// Random configurations built to hit the degenerate cases at once: occluder
// vertices snapped onto emitter vertices, emitter edges, the emitter plane, the
// rays from r through emitter vertices and the planes through r and emitter
// edges (exact D1/D2 events), at r itself; edges parallel to emitter edges;
// duplicated and edge-sharing triangles; slivers, tiny and huge triangles.
// An occluder triangle with two equal vertices followed by one holding that
// vertex last: merge_into_quad (now join_triangles) read b.v[-1] (UBSan in make sanitize found it
// through DegenerateFuzz); this case fails there without the fix.
TEST(VisiblePolygon, DegenerateTriangleBeforeANeighbourSharingItsVertex) {
  const std::vector<dvec3> emitter = {
      {-0.5, -0.5, 2.0}, {-0.5, 0.5, 2.0}, {0.5, 0.5, 2.0}, {0.5, -0.5, 2.0}};
  const dvec3 p(0.1, 0.05, 1.0), q(0.45, -0.1, 0.9);
  Triangle a, b;
  a.v = {p, p, q};
  b.v = {dvec3(-0.2, 0.1, 1.1), dvec3(0.3, 0.3, 1.2), p};
  const std::vector<Triangle> occluders = {a, b};
  const FormFactorGradient fg =
      visible_form_factor_gradient(dvec3(0.0), dvec3(0, 0, 1), emitter, occluders);
  const double unoccluded = form_factor(dvec3(0.0), dvec3(0, 0, 1), emitter);
  EXPECT_TRUE(std::isfinite(fg.value) && std::isfinite(glm::length(fg.gradient)));
  // b alone is in the way (a has no area).
  const FormFactorGradient b_only =
      visible_form_factor_gradient(dvec3(0.0), dvec3(0, 0, 1), emitter, std::vector<Triangle>{b});
  EXPECT_NEAR(fg.value, b_only.value, 1e-12);
  EXPECT_LT(fg.value, unoccluded);
}

TEST(VisiblePolygon, DegenerateFuzz) {
  std::mt19937_64 rng(37);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  int checked = 0, against_monte_carlo = 0, occluded = 0;
  double worst_sigmas = 0.0, largest_gradient = 0.0;
  for (int i = 0; i < 400; ++i) {
    Configuration c = random_configuration(rng, 0, 0.0);
    const std::size_t k = c.emitter.size();
    const dvec3 centre = (c.emitter[0] + c.emitter[k / 2]) * 0.5;
    const auto special_point = [&]() -> dvec3 {
      const std::size_t e = rng() % k;
      const dvec3 a = c.emitter[e], b = c.emitter[(e + 1) % k];
      const double t = uni(rng);
      switch (rng() % 8) {
        case 0:
          return a;  // emitter vertex
        case 1:
          return a + t * (b - a);  // on an emitter edge
        case 2:
          return c.r + (0.2 + 0.6 * t) * (a - c.r);  // on the ray to a vertex
        case 3:
          return c.r + (0.2 + 0.6 * t) * (a + uni(rng) * (b - a) - c.r);  // plane r, edge
        case 4:
          return c.r;  // at the receiver
        case 5:
          return centre + (uni(rng) - 0.5) * (b - a) + (uni(rng) - 0.5) * (a - centre);
        default:
          return c.r + (0.1 + 0.8 * t) * (centre - c.r) + random_in_ball(rng, 0.4);
      }
    };
    const int count = 1 + static_cast<int>(rng() % 6);
    for (int j = 0; j < count; ++j) {
      Triangle t;
      switch (rng() % 5) {
        case 0:  // three special points
          for (dvec3& v : t.v) v = special_point();
          break;
        case 1: {  // parallel to the emitter plane, one edge parallel to an emitter edge
          const std::size_t e = rng() % k;
          const dvec3 along = c.emitter[(e + 1) % k] - c.emitter[e];
          const double f = 0.2 + 0.6 * uni(rng);
          const dvec3 base = c.r + f * (centre - c.r);
          const dvec3 normal =
              glm::normalize(glm::cross(c.emitter[1] - c.emitter[0], c.emitter[2] - c.emitter[0]));
          t.v = {base, base + 0.5 * along, base + 0.4 * glm::cross(normal, along) + 0.1 * along};
          break;
        }
        case 2:  // sliver
          t.v[0] = special_point();
          t.v[1] = special_point();
          t.v[2] = t.v[0] + (t.v[1] - t.v[0]) * 0.5 + random_in_ball(rng, 1e-9);
          break;
        case 3:  // tiny or huge around a special point
          t.v[0] = special_point();
          t.v[1] = t.v[0] + random_in_ball(rng, uni(rng) < 0.5 ? 1e-8 : 5.0);
          t.v[2] = t.v[0] + random_in_ball(rng, uni(rng) < 0.5 ? 1e-8 : 5.0);
          break;
        default:  // shares an edge with the previous one, or duplicates it
          if (!c.occluders.empty()) {
            t = c.occluders.back();
            if (rng() % 2) t.v[2] = special_point();
          } else {
            for (dvec3& v : t.v) v = special_point();
          }
      }
      c.occluders.push_back(t);
    }
    const FormFactorGradient fg = visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders);
    const double unoccluded = form_factor_gradient(c.r, c.n, c.emitter).value;
    ++checked;
    occluded += fg.value < unoccluded;
    ASSERT_TRUE(std::isfinite(fg.value) && std::isfinite(glm::length(fg.gradient))) << "case " << i;
    EXPECT_GE(fg.value, 0.0) << "case " << i;
    EXPECT_LE(fg.value, unoccluded) << "case " << i;
    largest_gradient = std::max(largest_gradient, glm::length(fg.gradient));
    EXPECT_LT(glm::length(fg.gradient), 1e4) << "case " << i;
    if (i % 8 == 0) {
      const MonteCarlo mc = monte_carlo_form_factor(c.r, c.n, c.emitter, c.occluders, 100000, rng);
      const double sigmas = std::abs(fg.value - mc.mean) / (mc.standard_error + 1e-300);
      worst_sigmas = std::max(worst_sigmas, std::abs(fg.value - mc.mean) > 1e-12 ? sigmas : 0.0);
      EXPECT_LT(std::abs(fg.value - mc.mean), 4.5 * mc.standard_error + 1e-12)
          << "case " << i << ": exact " << fg.value << " mc " << mc.mean << " +- "
          << mc.standard_error;
      ++against_monte_carlo;
    }
  }
  std::printf(
      "degenerate fuzz: %d configurations (%d occluded), %d against Monte Carlo (worst "
      "%.2f sigma), largest |grad F| %.3g\n",
      checked, occluded, against_monte_carlo, worst_sigmas, largest_gradient);
  EXPECT_GT(occluded, checked / 2);
}

TEST(VisiblePolygon, MergedQuadsEqualTheirTriangles) {
  // Consecutive triangles forming a planar convex quad are subtracted as one
  // quad; given apart (interleaved with others) they are not. Same answer.
  std::mt19937_64 rng(59);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  int merged_cases = 0;
  for (int i = 0; i < 50; ++i) {
    Configuration c = random_configuration(rng, 0, 0.0);
    std::vector<Triangle> together;
    for (int b = 0; b < 3; ++b) {
      const dvec3 lo = c.r + (0.3 + 0.4 * uni(rng)) *
                                 (dvec3(0.4 * (uni(rng) - 0.5), 0.4 * (uni(rng) - 0.5), 2.0) - c.r);
      for (const Triangle& t : box(lo, lo + dvec3(0.1 + 0.3 * uni(rng), 0.1 + 0.3 * uni(rng), 0.2)))
        together.push_back(t);
    }
    std::vector<Triangle> apart;
    for (std::size_t k = 0; k < together.size(); k += 2) apart.push_back(together[k]);
    for (std::size_t k = 1; k < together.size(); k += 2) apart.push_back(together[k]);
    const FormFactorGradient a = visible_form_factor_gradient(c.r, c.n, c.emitter, together);
    const FormFactorGradient b = visible_form_factor_gradient(c.r, c.n, c.emitter, apart);
    EXPECT_NEAR(a.value, b.value, 1e-14) << i;
    EXPECT_NEAR(glm::length(a.gradient - b.gradient), 0.0, 1e-12) << i;
    merged_cases += a.value < form_factor(c.r, c.n, c.emitter);
  }
  EXPECT_GT(merged_cases, 25);
}

// A bumpy sheet of `cells` x `cells` non-planar quads, each as two
// consecutive triangles sharing its diagonal, oriented alike (a subdivided
// mesh as the add-on triangulates it), centred `along` of the way from r to
// the emitter: from 0 the sheet reaches behind r, where a fold's image is no
// longer the union of its triangles' images.
std::vector<Triangle> folded_sheet(std::mt19937_64& rng, const Configuration& c, int cells,
                                   double along) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const double size = 0.15 + 0.5 * uni(rng), bump = size / cells * (0.05 + 0.6 * uni(rng));
  const dvec3 centre = c.r + along * (dvec3(0.0, 0.0, 2.0) - c.r);
  std::vector<dvec3> grid;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i)
      grid.push_back(centre + dvec3(size * (static_cast<double>(i) / cells - 0.5),
                                    size * (static_cast<double>(j) / cells - 0.5),
                                    bump * (uni(rng) - 0.5)));
  std::vector<Triangle> sheet;
  const auto at = [&](int i, int j) { return grid[static_cast<size_t>(j * (cells + 1) + i)]; };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      sheet.push_back(Triangle{{at(i, j), at(i + 1, j), at(i + 1, j + 1)}});
      sheet.push_back(Triangle{{at(i, j), at(i + 1, j + 1), at(i, j + 1)}});
    }
  return sheet;
}

TEST(VisiblePolygon, FoldedQuadsEqualTheirTriangles) {
  // Consecutive triangles of a non-planar quad, wholly between r and the
  // emitter and seen from the same side, are subtracted as one quad where its
  // image is convex; kept apart (a triangle outside the shaft between them)
  // they are subtracted one by one. Same answer, for sheets between r and the
  // emitter and for sheets around r (a fold reaching behind r joined anyway
  // cast the wrong shadow: parts of Suzanne's inside came out up to 46
  // times too bright).
  std::mt19937_64 rng(61);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  const Triangle outside{{dvec3(50.0, 50.0, 1.0), dvec3(51.0, 50.0, 1.0), dvec3(50.0, 51.0, 1.0)}};
  int occluded = 0;
  for (int i = 0; i < 200; ++i) {
    const Configuration c = random_configuration(rng, 0, 0.0);
    const double along = i % 2 ? 0.2 + 0.6 * uni(rng) : 0.06 * (uni(rng) - 0.3);
    const std::vector<Triangle> together = folded_sheet(rng, c, 1 + i % 4, along);
    std::vector<Triangle> apart;
    for (const Triangle& t : together) {
      apart.push_back(t);
      apart.push_back(outside);
    }
    const FormFactorGradient a = visible_form_factor_gradient(c.r, c.n, c.emitter, together);
    const FormFactorGradient b = visible_form_factor_gradient(c.r, c.n, c.emitter, apart);
    EXPECT_NEAR(a.value, b.value, 1e-13 + 1e-12 * b.value) << i;
    EXPECT_NEAR(glm::length(a.gradient - b.gradient), 0.0, 1e-11 * (1.0 + glm::length(b.gradient)))
        << i;
    occluded += a.value < form_factor(c.r, c.n, c.emitter);
  }
  EXPECT_GT(occluded, 150);
}

TEST(VisiblePolygon, ManyOverlappingOccluders) {
  std::mt19937_64 rng(19);
  for (int i = 0; i < 4; ++i) {
    Configuration c = random_configuration(rng, 40, 0.2);
    // Add copies, sharing vertices and edges with the originals.
    for (int k = 0; k < 10; ++k) {
      Triangle t = c.occluders[k];
      t.v[2] = c.occluders[k + 10].v[0];
      c.occluders.push_back(t);
    }
    expect_sane(c.r, c.n, c.emitter, c.occluders, 200000, "many occluders");
  }
}

TEST(VisiblePolygon, ScaleInvariance) {
  const dvec3 r(0.03, -0.02, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
  const Polygon emitter = math_emitter();
  std::vector<Triangle> occluders = box({0.0, -0.1, 0.8}, {0.3, 0.2, 1.2});
  occluders.push_back(math_occluder());
  const FormFactorGradient base = visible_form_factor_gradient(r, n, emitter, occluders);
  for (const double scale : {1e-6, 1e-3, 1e3, 1e6}) {
    Polygon e = emitter;
    for (dvec3& v : e) v *= scale;
    std::vector<Triangle> o = occluders;
    for (Triangle& t : o)
      for (dvec3& v : t.v) v *= scale;
    const FormFactorGradient fg = visible_form_factor_gradient(r * scale, n, e, o);
    EXPECT_NEAR(fg.value, base.value, 1e-13 * base.value) << scale;
    EXPECT_NEAR(glm::length(fg.gradient * scale - base.gradient), 0.0, 1e-11) << scale;
  }
}

TEST(VisiblePolygon, TranslationInvariance) {
  // Far from the origin only the coordinates' own rounding remains (1e-16 of
  // the offset): an offset of 1e6 costs about 1e-10.
  const dvec3 r(0.03, -0.02, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
  const Polygon emitter = math_emitter();
  const std::vector<Triangle> occluders{
      math_occluder(),
      Triangle{{dvec3(-0.3, -0.2, 1.0), dvec3(0.0, -0.5, 1.0), dvec3(0.25, 0.0, 1.0)}},
      Triangle{{dvec3(-0.5, 0.5, 2.0), dvec3(0.0, 0.0, 1.5), dvec3(-0.5, -0.5, 2.0)}}};
  const FormFactorGradient base = visible_form_factor_gradient(r, n, emitter, occluders);
  for (const double offset : {1e2, 1e4, 1e6}) {
    const dvec3 t(offset, -offset, 0.5 * offset);
    Polygon e = emitter;
    for (dvec3& v : e) v += t;
    std::vector<Triangle> o = occluders;
    for (Triangle& tri : o)
      for (dvec3& v : tri.v) v += t;
    const FormFactorGradient fg = visible_form_factor_gradient(r + t, n, e, o);
    EXPECT_NEAR(fg.value, base.value, 1e-15 * offset * base.value + 1e-16) << offset;
    EXPECT_NEAR(glm::length(fg.gradient - base.gradient), 0.0, 1e-14 * offset) << offset;
  }
}

TEST(VisiblePolygon, SameResultsFromManyThreads) {
  // Per-thread workspaces: evaluations in parallel give the serial answers, bit for bit.
  std::mt19937_64 rng(47);
  std::vector<Configuration> configurations;
  for (int i = 0; i < 256; ++i) configurations.push_back(random_configuration(rng, 1 + i % 8, 0.3));
  std::vector<FormFactorGradient> serial(configurations.size()), parallel(configurations.size());
  for (std::size_t i = 0; i < configurations.size(); ++i) {
    const Configuration& c = configurations[i];
    serial[i] = visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders);
  }
  tbb::parallel_for(std::size_t(0), configurations.size(), [&](std::size_t i) {
    const Configuration& c = configurations[i];
    parallel[i] = visible_form_factor_gradient(c.r, c.n, c.emitter, c.occluders);
  });
  for (std::size_t i = 0; i < configurations.size(); ++i) {
    EXPECT_EQ(serial[i].value, parallel[i].value) << i;
    EXPECT_EQ(serial[i].gradient, parallel[i].gradient) << i;
  }
}

// --- Sampled visibility -------------------------------------------------------------

TEST(SampledVisibility, NoOccluderGivesTheUnoccludedFormFactor) {
  const dvec3 r(0.03, -0.02, 0.0);
  const dvec3 n = glm::normalize(dvec3(0.1, -0.2, 1.0));
  const Polygon emitter = math_emitter();
  const FormFactorGradient exact = form_factor_gradient(r, n, emitter);
  const RayScene empty(std::vector<Triangle>{});
  const FormFactorGradient sampled = sampled_form_factor_gradient(r, n, emitter, empty, {});
  EXPECT_EQ(sampled.value, exact.value);
  EXPECT_EQ(sampled.gradient, exact.gradient);
}

TEST(SampledVisibility, ConvergesToExactAsRaysGrow) {
  std::mt19937_64 rng(29);
  const std::vector<int> ray_counts{16, 64, 256, 1024, 4096, 16384};
  std::vector<double> embree_error(ray_counts.size(), 0.0), own_error(ray_counts.size(), 0.0);
  const int configurations = 24;
  for (int i = 0; i < configurations; ++i) {
    const Configuration c = random_configuration(rng, 1 + i % 4, 0.3);
    const double exact = visible_f(c.r, c.n, c.emitter, c.occluders);
    const double unoccluded = form_factor_gradient(c.r, c.n, c.emitter).value;
    const RayScene scene(c.occluders);
    for (std::size_t k = 0; k < ray_counts.size(); ++k) {
      SampledVisibilityOptions options;
      options.rays = ray_counts[k];
      options.seed = static_cast<std::uint64_t>(i);
      double open_a = -1.0, open_b = -1.0;
      const double a = sampled_form_factor_gradient(c.r, c.n, c.emitter, scene, options, kNoFace,
                                                    kNoFace, &open_a)
                           .value;
      const double b =
          sampled_form_factor_gradient(c.r, c.n, c.emitter, c.occluders, options, &open_b).value;
      EXPECT_EQ(open_a, unoccluded);
      EXPECT_EQ(open_b, unoccluded);
      EXPECT_GE(a, 0.0);
      EXPECT_LE(a, unoccluded);
      embree_error[k] += std::abs(a - exact) / unoccluded / configurations;
      own_error[k] += std::abs(b - exact) / unoccluded / configurations;
    }
  }
  for (std::size_t k = 0; k < ray_counts.size(); ++k)
    std::printf(
        "sampled visibility, %5d rays: mean |F - exact| / F_unoccluded = %.2e (Embree), %.2e (own "
        "rays)\n",
        ray_counts[k], embree_error[k], own_error[k]);
  // Stratified sampling of a shadow boundary converges like N^-3/4: 256 times
  // more rays should gain far more than a factor 10.
  EXPECT_LT(embree_error.back(), 0.1 * embree_error[1]);
  EXPECT_LT(own_error.back(), 0.1 * own_error[1]);
  EXPECT_LT(embree_error.back(), 2e-3);
  EXPECT_LT(own_error.back(), 2e-3);
}

TEST(SampledVisibility, EmbreeAgreesWithDoublePrecisionRays) {
  std::mt19937_64 rng(31);
  int rays = 0, disagreements = 0;
  for (int i = 0; i < 20; ++i) {
    const Configuration c = random_configuration(rng, 6, 0.3);
    const RayScene scene(c.occluders);
    SampledVisibilityOptions options;
    options.rays = 1000;
    const EmitterSamples samples = sample_emitter(c.r, c.n, c.emitter, options);
    for (const dvec3& y : samples.points) {
      bool own = false;
      for (const Triangle& t : c.occluders) own = own || segment_hits_triangle(c.r, y, t);
      disagreements += own != scene.occluded(c.r, y);
      ++rays;
    }
  }
  std::printf("Embree vs double-precision shadow rays: %d of %d disagree\n", disagreements, rays);
  EXPECT_LE(disagreements, rays / 2000);
}

TEST(SampledVisibility, VectorisedRaysAgreeWithTheReferenceTest) {
  // visible_fraction over candidates (origin fixed, vectorised) against
  // segment_hits_triangle ray by ray.
  std::mt19937_64 rng(53);
  for (int i = 0; i < 40; ++i) {
    const Configuration c = random_configuration(rng, 1 + i % 12, 0.3);
    SampledVisibilityOptions options;
    options.rays = 500;
    options.seed = static_cast<std::uint64_t>(i);
    const EmitterSamples samples = sample_emitter(c.r, c.n, c.emitter, options);
    std::vector<std::uint8_t> blocked(samples.points.size(), 0);
    for (std::size_t k = 0; k < samples.points.size(); ++k)
      for (const Triangle& t : c.occluders)
        blocked[k] = blocked[k] || segment_hits_triangle(c.r, samples.points[k], t);
    EXPECT_DOUBLE_EQ(visible_fraction(c.occluders, c.r, samples),
                     visible_fraction(samples, blocked))
        << "configuration " << i;
  }
}

TEST(SampledVisibility, OwnFacesNeverShadowTheLink) {
  // A blocker tagged with the receiver's face (or the emitter's) is ignored.
  const std::vector<Triangle> triangles{
      Triangle{{dvec3(-5, -5, 1), dvec3(5, -5, 1), dvec3(0, 5, 1)}}};
  const std::vector<std::uint32_t> face{7};
  const RayScene scene(triangles, face);
  const dvec3 from(0.0, 0.0, 0.0), to(0.1, 0.2, 2.0);
  EXPECT_TRUE(scene.occluded(from, to));
  EXPECT_FALSE(scene.occluded(from, to, 7));
  EXPECT_FALSE(scene.occluded(from, to, kNoFace, 7));
  std::vector<dvec3> targets(20, to);
  std::vector<std::uint8_t> blocked(20, 0);
  scene.occluded(from, targets, blocked, 3, 7);
  for (std::uint8_t b : blocked) EXPECT_EQ(b, 0);
  scene.occluded(from, targets, blocked);
  for (std::uint8_t b : blocked) EXPECT_EQ(b, 1);
}

}  // namespace
}  // namespace radiosity
