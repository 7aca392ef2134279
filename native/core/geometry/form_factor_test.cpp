// Point-to-polygon form factor and gradient kernels against closed forms,
// finite differences, brute-force cubature, extremes and invariances.
#include "core/geometry/form_factor.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <glm/gtc/matrix_transform.hpp>

#include "core/geometry/test_shapes.h"

namespace radiosity {
namespace {

using test::central_difference;
using test::corner_parallel;
using test::perpendicular;
using test::rectangle_facing_down;

constexpr dvec3 kUp(0, 0, 1);

void expect_relative(double actual, double expected, double tolerance) {
  EXPECT_NEAR(actual, expected, tolerance * std::abs(expected)) << "expected " << expected;
}

void expect_vec_near(const dvec3& actual, const dvec3& expected, double tolerance) {
  EXPECT_LE(glm::length(actual - expected), tolerance * glm::length(expected))
      << "actual (" << actual.x << ", " << actual.y << ", " << actual.z << ") expected ("
      << expected.x << ", " << expected.y << ", " << expected.z << ")";
}

std::vector<ContourVertex> as_contour(const std::vector<dvec3>& polygon) {
  std::vector<ContourVertex> contour;
  for (const dvec3& v : polygon) contour.push_back(ContourVertex::intrinsic(v));
  return contour;
}

// --- Closed forms (MATH.md s5) ---------------------------------------------------

TEST(FormFactor, ParallelCentredMatchesClosedForm) {
  for (auto [a, b, c] : {std::array{1.0, 1.0, 1.0}, {2.0, 1.0, 0.5}, {0.3, 4.0, 2.5}}) {
    const auto quad = rectangle_facing_down(-a / 2, a / 2, -b / 2, b / 2, c);
    expect_relative(form_factor(dvec3(0), kUp, quad), 4 * corner_parallel(a / 2, b / 2, c), 1e-12);
  }
  expect_relative(form_factor(dvec3(0), kUp, rectangle_facing_down(-.5, .5, -.5, .5, 1)),
                  0.23945647046077351, 1e-12);
  expect_relative(form_factor(dvec3(0), kUp, rectangle_facing_down(-1, 1, -.5, .5, .5)),
                  0.66950003965753502, 1e-12);
}

TEST(FormFactor, BelowCornerMatchesClosedForm) {
  for (auto [a, b, c, reference] : {std::array{1.0, 1.0, 1.0, 0.13853160599489298},
                                    {2.0, 1.0, 0.5, 0.22077762233476159},
                                    {1.0, 3.0, 2.0, 0.10204094980924763}}) {
    const auto quad = rectangle_facing_down(0, a, 0, b, c);
    expect_relative(form_factor(dvec3(0), kUp, quad), corner_parallel(a, b, c), 1e-12);
    expect_relative(form_factor(dvec3(0), kUp, quad), reference, 1e-12);
  }
}

// Rectangle in the plane y = c facing -y, x in [0, b], z in [0, a]: it shares the
// line y = c, z = 0 with the receiver plane.
std::vector<dvec3> perpendicular_rectangle(double a, double b, double c) {
  return {{0, c, 0}, {b, c, 0}, {b, c, a}, {0, c, a}};
}

// The layout of MATH.md's reference gradients: the wall in the plane x = c,
// y in [0, b], facing -x.
std::vector<dvec3> perpendicular_rectangle_x(double a, double b, double c) {
  return {{c, 0, 0}, {c, 0, a}, {c, b, a}, {c, b, 0}};
}

TEST(FormFactor, PerpendicularMatchesClosedForm) {
  for (auto [a, b, c, reference] :
       {std::array{1.0, 1.0, 1.0, 0.055734197002553512}, {2.0, 1.0, 0.5, 0.15877480451429929}}) {
    const auto quad = perpendicular_rectangle(a, b, c);
    expect_relative(form_factor(dvec3(0), kUp, quad), perpendicular(a, b, c), 1e-12);
    expect_relative(form_factor(dvec3(0), kUp, quad), reference, 1e-12);
  }
}

TEST(FormFactor, EmitterStraddlingTheHorizonKeepsTheUpperPart) {
  // The same perpendicular wall extended below the receiver plane: only the part
  // above the horizon counts.
  const double a = 1.3, b = 0.7, c = 0.4;
  const std::vector<dvec3> wall = {{0, c, -2}, {b, c, -2}, {b, c, a}, {0, c, a}};
  expect_relative(form_factor(dvec3(0), kUp, wall), perpendicular(a, b, c), 1e-12);
  const auto [value, gradient] = form_factor_gradient(dvec3(0), kUp, wall);
  expect_relative(value, perpendicular(a, b, c), 1e-12);
  const dvec3 fd =
      central_difference([&](const dvec3& r) { return form_factor(r, kUp, wall); }, dvec3(0), 1e-6);
  expect_vec_near(gradient, fd, 1e-7);
}

// Inside a 2 x 1 x 1.5 box every wall faces inwards; from any interior point the
// six form factors sum to 1.
std::array<std::vector<dvec3>, 6> box_walls(double w, double d, double h) {
  return {{{{0, 0, 0}, {w, 0, 0}, {w, d, 0}, {0, d, 0}},    // z = 0 facing +z
           {{0, 0, h}, {0, d, h}, {w, d, h}, {w, 0, h}},    // z = h facing -z
           {{0, 0, 0}, {0, 0, h}, {w, 0, h}, {w, 0, 0}},    // y = 0 facing +y
           {{0, d, 0}, {w, d, 0}, {w, d, h}, {0, d, h}},    // y = d facing -y
           {{0, 0, 0}, {0, d, 0}, {0, d, h}, {0, 0, h}},    // x = 0 facing +x
           {{w, 0, 0}, {w, 0, h}, {w, d, h}, {w, d, 0}}}};  // x = w facing -x
}

TEST(FormFactor, BoxWallsMatchReferenceAndSumToOne) {
  const auto walls = box_walls(2, 1, 1.5);
  const double reference[6] = {
      0, 0.19708576974, 0.364081708387, 0.224651995337, 0.150446513775, 0.063734012761};
  double sum = 0;
  for (int i = 0; i < 6; ++i) {
    const double f = form_factor({0.7, 0.3, 0}, kUp, walls[i]);
    EXPECT_NEAR(f, reference[i], 1e-11);
    sum += f;
  }
  EXPECT_NEAR(sum, 1.0, 1e-12);

  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.02, 0.98);
  for (int trial = 0; trial < 200; ++trial) {
    const dvec3 r{2 * u(rng), u(rng), 1.5 * u(rng)};
    const dvec3 n = test::random_unit(rng);
    double total = 0;
    dvec3 gradient_total(0.0);
    for (const auto& wall : walls) {
      const auto result = form_factor_gradient(r, n, wall);
      total += result.value;
      gradient_total += result.gradient;
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
    // The sum is constant, so its gradient vanishes.
    EXPECT_LT(glm::length(gradient_total), 1e-10);
  }
}

// --- Reference gradients (MATH.md s5) -----------------------------------------------

TEST(FormFactorGradient, MatchesReferenceValues) {
  struct Case {
    std::vector<dvec3> polygon;
    double value;
    dvec3 gradient;
  };
  const Case cases[] = {
      {rectangle_facing_down(-.5, .5, -.5, .5, 1), 0.23945647046077351, {0, 0, 0.361330448999974}},
      {rectangle_facing_down(-1, 1, -.5, .5, .5), 0.66950003965753502, {0, 0, 0.822915384485942}},
      {rectangle_facing_down(0, 1, 0, 1, 1),
       0.13853160599489298,
       {0.143418746198575, 0.143418746198575, 0.122317450694745}},
      {perpendicular_rectangle_x(1, 1, 1),
       0.055734197002553512,
       {0.087684549196022, 0.053051647697298, -0.061158725347372}},
      {perpendicular_rectangle_x(2, 1, .5),
       0.15877480451429929,
       {0.158356492466451, 0.251081411622844, -0.015336941312133}},
  };
  for (const Case& c : cases) {
    const auto robust = form_factor_gradient(dvec3(0), kUp, c.polygon);
    expect_relative(robust.value, c.value, 1e-12);
    expect_vec_near(robust.gradient, c.gradient, 1e-11);
    const auto general = form_factor_gradient(dvec3(0), kUp, as_contour(c.polygon));
    expect_relative(general.value, c.value, 1e-12);
    expect_vec_near(general.gradient, c.gradient, 1e-11);
  }
}

// --- Randomised: gradient against central finite differences --------------------------

struct ErrorStats {
  double worst = 0;
  int checked = 0;
  int skipped = 0;
};

TEST(FormFactorGradient, MatchesFiniteDifferencesOnRandomConfigurations) {
  std::mt19937_64 rng(20001);
  ErrorStats robust_stats, general_stats;
  const int kConfigurations = 12000;
  for (int trial = 0; trial < kConfigurations; ++trial) {
    const auto c = test::random_configuration(rng, /*convex=*/trial % 3 != 0);
    const auto f = [&](const dvec3& r) { return form_factor(r, c.normal, c.polygon); };
    const double h = 1e-6 * c.scale;
    const dvec3 fd = central_difference(f, c.point, h);
    const dvec3 fd_half = central_difference(f, c.point, h / 2);
    const auto robust = form_factor_gradient(c.point, c.normal, c.polygon);
    const auto general = form_factor_gradient(c.point, c.normal, as_contour(c.polygon));
    ASSERT_NEAR(robust.value, f(c.point), 1e-15);
    ASSERT_NEAR(general.value, f(c.point), 1e-14);
    // Near a second-derivative discontinuity (a vertex crossing the horizon) or
    // where F is too small to difference, the two step sizes disagree: skip.
    const double magnitude = glm::length(fd);
    if (magnitude < 1e-6 / c.scale || glm::length(fd - fd_half) > 1e-8 * magnitude) {
      ++robust_stats.skipped;
      continue;
    }
    for (auto [stats, gradient] :
         {std::pair{&robust_stats, robust.gradient}, std::pair{&general_stats, general.gradient}}) {
      const double error = glm::length(gradient - fd) / magnitude;
      stats->worst = std::max(stats->worst, error);
      ++stats->checked;
      EXPECT_LT(error, 1e-6) << "trial " << trial;
    }
  }
  std::printf(
      "gradient vs FD: %d checked, %d skipped; worst relative error robust %.3g, general %.3g\n",
      robust_stats.checked, robust_stats.skipped, robust_stats.worst, general_stats.worst);
  EXPECT_GE(robust_stats.checked, 10000);
}

// --- Independent check: brute-force cubature over the emitter ---------------------------

// Integrand of the form factor over the emitter: max(0, cos_r) cos_e / (pi d^2).
double kernel(const dvec3& r, const dvec3& n, const dvec3& x, const dvec3& emitter_normal) {
  const dvec3 d = x - r;
  const double d2 = glm::dot(d, d);
  const double cos_r = std::max(0.0, glm::dot(n, d)) / std::sqrt(d2);
  const double cos_e = std::max(0.0, -glm::dot(emitter_normal, d)) / std::sqrt(d2);
  return cos_r * cos_e / (kPi * d2);
}

// Degree-5 seven-point rule on a triangle (Radon), subdivided adaptively in four.
double integrate_triangle(const dvec3& r, const dvec3& n, const dvec3& ne, const dvec3& a,
                          const dvec3& b, const dvec3& c, double tolerance, int depth) {
  const auto rule = [&](const dvec3& p, const dvec3& q, const dvec3& s) {
    const double area = 0.5 * glm::length(glm::cross(q - p, s - p));
    const double w0 = 9.0 / 40, w1 = (155 - std::sqrt(15.0)) / 1200,
                 w2 = (155 + std::sqrt(15.0)) / 1200;
    const double a1 = (6 - std::sqrt(15.0)) / 21, a2 = (6 + std::sqrt(15.0)) / 21;
    const auto at = [&](double l1, double l2) {
      return kernel(r, n, p * (1 - l1 - l2) + q * l1 + s * l2, ne);
    };
    double sum = w0 * at(1.0 / 3, 1.0 / 3);
    sum += w1 * (at(a1, a1) + at(1 - 2 * a1, a1) + at(a1, 1 - 2 * a1));
    sum += w2 * (at(a2, a2) + at(1 - 2 * a2, a2) + at(a2, 1 - 2 * a2));
    return sum * area;
  };
  const dvec3 ab = (a + b) / 2.0, bc = (b + c) / 2.0, ca = (c + a) / 2.0;
  const double whole = rule(a, b, c);
  const double parts = rule(a, ab, ca) + rule(ab, b, bc) + rule(ca, bc, c) + rule(ab, bc, ca);
  if (depth >= 12 || (depth >= 0 && std::abs(whole - parts) < tolerance)) return parts;
  return integrate_triangle(r, n, ne, a, ab, ca, tolerance / 4, depth + 1) +
         integrate_triangle(r, n, ne, ab, b, bc, tolerance / 4, depth + 1) +
         integrate_triangle(r, n, ne, ca, bc, c, tolerance / 4, depth + 1) +
         integrate_triangle(r, n, ne, ab, bc, ca, tolerance / 4, depth + 1);
}

// The part of triangle (a, b, c) where h(x) = n.(x - r) >= 0, as triangles: the
// integrand has a kink along the horizon, so cubature integrates each side apart.
std::vector<std::array<dvec3, 3>> split_at_horizon(const dvec3& r, const dvec3& n,
                                                   const std::array<dvec3, 3>& t) {
  std::vector<dvec3> kept;
  for (int i = 0; i < 3; ++i) {
    const dvec3 &p = t[i], &q = t[(i + 1) % 3];
    const double hp = glm::dot(n, p - r), hq = glm::dot(n, q - r);
    if (hp >= 0) kept.push_back(p);
    if ((hp >= 0) != (hq >= 0)) kept.push_back(p + (q - p) * (hp / (hp - hq)));
  }
  std::vector<std::array<dvec3, 3>> out;
  for (size_t i = 1; i + 1 < kept.size(); ++i) out.push_back({kept[0], kept[i], kept[i + 1]});
  return out;
}

double brute_force_form_factor(const test::RandomConfiguration& c) {
  double sum = 0;
  for (size_t i = 1; i + 1 < c.polygon.size(); ++i) {
    for (const auto& t :
         split_at_horizon(c.point, c.normal, {c.polygon[0], c.polygon[i], c.polygon[i + 1]})) {
      sum += integrate_triangle(c.point, c.normal, c.emitter_normal, t[0], t[1], t[2], 1e-11, -1);
    }
  }
  return sum;
}

TEST(FormFactor, AgreesWithBruteForceCubature) {
  std::mt19937_64 rng(31337);
  double worst = 0;
  int checked = 0;
  while (checked < 200) {
    const auto c = test::random_configuration(rng, /*convex=*/true);
    const double exact = form_factor(c.point, c.normal, c.polygon);
    if (exact == 0.0) continue;
    ++checked;
    const double error = std::abs(exact - brute_force_form_factor(c));
    worst = std::max(worst, error / exact);
    EXPECT_LT(error, 1e-12 + 1e-8 * exact) << "exact " << exact;
  }
  std::printf("form factor vs cubature: worst relative error %.3g over %d configurations\n", worst,
              checked);
}

// --- Extremes ---------------------------------------------------------------------------

TEST(FormFactorExtremes, ScaleFrom1e9To1e9) {
  const double reference = 0.13853160599489298;
  for (double s = 1e-9; s <= 1e9; s *= 10) {
    const auto quad = rectangle_facing_down(0, s, 0, s, s);
    const auto [value, gradient] = form_factor_gradient(dvec3(0), kUp, quad);
    expect_relative(value, reference, 1e-12);
    expect_vec_near(gradient * s, {0.143418746198575, 0.143418746198575, 0.122317450694745}, 1e-11);
  }
}

TEST(FormFactorExtremes, SizeOverDistanceFrom1e9To1e9) {
  // A square of side a at distance c, for a/c over 18 decades: matches the closed form.
  for (double ratio = 1e-9; ratio <= 1e9; ratio *= 10) {
    const double c = 1.0, a = ratio * c;
    const auto quad = rectangle_facing_down(-a / 2, a / 2, -a / 2, a / 2, c);
    const auto [value, gradient] = form_factor_gradient(dvec3(0), kUp, quad);
    const double expected = 4 * corner_parallel(a / 2, a / 2, c);
    expect_relative(value, expected, 1e-6);
    EXPECT_TRUE(std::isfinite(gradient.z));
    const auto general = form_factor_gradient(dvec3(0), kUp, as_contour(quad));
    expect_relative(general.value, expected, 1e-6);
    EXPECT_TRUE(std::isfinite(glm::length(general.gradient)));
  }
}

TEST(FormFactorExtremes, ScaleFrom1e100To1e100) {
  // The edge terms hold products of four lengths, which underflowed below
  // about 1e-77 (F = -0.24 for a polygon 4e-81 across, libFuzzer kernels
  // crash-8fd16867) and overflow above about 1e77: such input is rescaled.
  const double reference = 0.13853160599489298;
  for (double s = 1e-100; s <= 1e100; s *= 1e10) {
    const auto quad = rectangle_facing_down(0, s, 0, s, s);
    EXPECT_NEAR(form_factor(dvec3(0), kUp, quad), reference, 1e-12 * reference) << "scale " << s;
    const auto [value, gradient] = form_factor_gradient(dvec3(0), kUp, quad);
    EXPECT_NEAR(value, reference, 1e-12 * reference) << "scale " << s;
    expect_vec_near(gradient * s, {0.143418746198575, 0.143418746198575, 0.122317450694745}, 1e-11);
  }
  // The fuzzer's 14-gon, 4e-81 across, seen from 6e-9 of its size above it:
  // the same F as scaled by 2^268 (exact) to unit size, and that one is the
  // limit of a receiver on a plane, tilted by beta from facing it, that the
  // emitter all but fills: (1 - cos beta) / 2 (the plane's part of the
  // hemisphere; cubature does not converge this close to the emitter).
  const std::vector<dvec3> tiny = {
      {2.2238036002151056e-81, 6.9709482627161094e-84, 2.0549185278933649e-81},
      {3.2319079304955273e-81, 3.7066964068998719e-82, 2.0547553399032966e-81},
      {3.7611076748717400e-81, 9.1017432135807313e-82, 2.0546282081473424e-81},
      {4.0887086236281565e-81, 1.7639021879165663e-81, 2.0544876787332867e-81},
      {4.0134482386102686e-81, 2.6752251471732768e-81, 2.0543882217640257e-81},
      {3.5502327620789191e-81, 3.4636445104047843e-81, 2.0543495359120816e-81},
      {2.7908077001261476e-81, 3.9730041533941504e-81, 2.0543792833848825e-81},
      {1.8855865000088713e-81, 4.1024191519612603e-81, 2.0544715723306115e-81},
      {1.0138593222197791e-81, 3.8262572784691004e-81, 2.0546081237917173e-81},
      {3.4828242535223661e-82, 3.1992157788659031e-81, 2.0547618920766340e-81},
      {2.0681476595819890e-83, 2.3454879123074099e-81, 2.0549024214906897e-81},
      {9.5941861613707862e-83, 1.4341649530506996e-81, 2.0550018784599507e-81},
      {5.5915733814505661e-82, 6.4574558981919306e-82, 2.0550405643118948e-81},
      {1.3185824000978293e-81, 1.3638594682982606e-82, 2.0550108168390939e-81}};
  const dvec3 r(2.0549049897155772e-81, 2.0546950501119882e-81, 2.0546950501119882e-81);
  const dvec3 n = glm::normalize(dvec3(1.0));
  std::vector<dvec3> unit;
  for (const dvec3& v : tiny) unit.push_back(v * 0x1p268);
  const double f = form_factor(r, n, tiny);
  const double f_unit = form_factor(r * 0x1p268, n, unit);
  EXPECT_NEAR(f, f_unit, 1e-12);
  dvec3 area(0.0);
  for (size_t i = 1; i + 1 < unit.size(); ++i)
    area += glm::cross(unit[i] - unit[0], unit[i + 1] - unit[0]);
  EXPECT_NEAR(f_unit, 0.5 * (1.0 - glm::dot(n, glm::normalize(area))), 1e-6);
}

TEST(FormFactorExtremes, ReceiverOnAVertexOfASliverSeesNothing) {
  // A triangle 19 long and 2e-4 wide; its normal from the long edges is off
  // by 1e-11, which put a receiver on vertex 2 2e-11 "in front" of v0's
  // plane: F = -0.033 (atheris, finding 1; 109 findings in a 600 s run).
  const std::vector<dvec3> sliver = {{9.99938964836474, -9.842458791099524, -9.99999999941564},
                                     {2.8625488677062094, 2.862745098039216, 2.862745098039216},
                                     {2.862745098039216, 2.862745098039216, 2.862745098039216}};
  const dvec3 n = glm::normalize(dvec3(-9.999999999999954, -7.490196078431373, -10.0));
  for (const dvec3& r :
       {sliver[2], dvec3(2.862745098039219, 2.8627450980392064, 2.862745098039214)}) {
    EXPECT_EQ(form_factor(r, n, sliver), 0.0);
    EXPECT_EQ(form_factor_gradient(r, n, sliver).value, 0.0);
    EXPECT_EQ(form_factor_gradient(r, n, as_contour(sliver)).value, 0.0);
  }
  // Just off the vertex, in front (1e-3 along the normal, facing the
  // triangle), F is positive and the sum over the sliver's two halves.
  const dvec3 normal = glm::normalize(glm::cross(sliver[2] - sliver[1], sliver[0] - sliver[1]));
  const dvec3 r = sliver[2] + 1e-3 * normal - 1e-3 * glm::normalize(sliver[2] - sliver[0]);
  const dvec3 middle = 0.5 * (sliver[0] + sliver[1]);
  const double f = form_factor(r, -normal, sliver);
  EXPECT_GT(f, 0.05);
  EXPECT_NEAR(f,
              form_factor(r, -normal, std::vector<dvec3>{sliver[0], middle, sliver[2]}) +
                  form_factor(r, -normal, std::vector<dvec3>{middle, sliver[1], sliver[2]}),
              1e-12);
}

TEST(FormFactorExtremes, ReceiverWithinATwistedCornerSeesNothing) {
  // Planar to 1e-9 of its size (4), but its corner at the origin, 6e-9
  // across, drops 3e-9: a receiver 3e-10 above that corner is within the
  // polygon's thickness, on it (F was -6.5e-4; libFuzzer kernels, crash-dd8d717d).
  const std::vector<dvec3> p = {
      {-4.7165402388330148e-10, 2.9334841597860532e-310, 0.0},
      {0.0, -4.0, -3.2099434464697876e-09},
      {-3.2096664895593493e-09, 4.3486241962839191e-09, -2.1119385739660850e-09},
      {-4.0078836909046392e-09, -3.8029735139882818e-09, 1.1701537641651122e-09}};
  EXPECT_EQ(form_factor(dvec3(0.0), kUp, p), 0.0);
  EXPECT_EQ(form_factor_gradient(dvec3(0.0), kUp, p).value, 0.0);
}

TEST(FormFactorExtremes, CoordinatesOffsetBy1e6) {
  const dvec3 offset(1e6, -1e6, 1e6);
  auto quad = rectangle_facing_down(0, 1, 0, 1, 1);
  for (dvec3& v : quad) v += offset;
  const auto [value, gradient] = form_factor_gradient(offset, kUp, quad);
  expect_relative(value, 0.13853160599489298, 1e-9);
  expect_vec_near(gradient, {0.143418746198575, 0.143418746198575, 0.122317450694745}, 1e-8);
}

TEST(FormFactorExtremes, TinySquareSubtending1e8Radians) {
  const double a = 1e-8;
  const auto quad = rectangle_facing_down(-a / 2, a / 2, -a / 2, a / 2, 1);
  expect_relative(form_factor(dvec3(0), kUp, quad), 3.183098861838e-17, 1e-6);
  expect_relative(form_factor_gradient(dvec3(0), kUp, quad).value, 3.183098861838e-17, 1e-6);
  expect_relative(form_factor_gradient(dvec3(0), kUp, as_contour(quad)).value, 3.183098861838e-17,
                  1e-6);
  // Far away and off-axis, where the edge terms cancel most: A cos cos / (pi d^2).
  const dvec3 r(3, -2, -5);
  const dvec3 d = dvec3(0, 0, 1) - r;
  const double dist = glm::length(d);
  const double approx = a * a * (d.z / dist) * (d.z / dist) / (kPi * dist * dist);
  expect_relative(form_factor(r, kUp, quad), approx, 1e-6);
}

TEST(FormFactorExtremes, ReceiverOnTheEmitterPlaneGivesZero) {
  const auto quad = rectangle_facing_down(-1, 1, -1, 1, 0);
  for (dvec3 r :
       {dvec3(0, 0, 0), dvec3(1, 0, 0), dvec3(1, 1, 0), dvec3(3, 0, 0), dvec3(0.5, 0.5, 1e-12)}) {
    for (dvec3 n : {dvec3(0, 0, 1), dvec3(0, 0, -1), glm::normalize(dvec3(1, 0, -1))}) {
      EXPECT_EQ(form_factor(r, n, quad), 0.0);
      const auto robust = form_factor_gradient(r, n, quad);
      const auto general = form_factor_gradient(r, n, as_contour(quad));
      EXPECT_EQ(robust.value, 0.0);
      EXPECT_EQ(glm::length(robust.gradient), 0.0);
      EXPECT_EQ(general.value, 0.0);
    }
  }
  // Behind the emitter: nothing.
  EXPECT_EQ(form_factor({0, 0, 1}, kUp, quad), 0.0);
}

TEST(FormFactorExtremes, ReceiverOnAnEdgeOrVertexIsFinite) {
  // The floor point lies on the shared line of a wall: on the wall's plane, F = 0.
  const auto wall = perpendicular_rectangle(1, 1, 0);  // plane y = 0
  for (dvec3 r : {dvec3(0.5, 0, 0), dvec3(0, 0, 0), dvec3(1, 0, 0)}) {
    const auto result = form_factor_gradient(r, kUp, wall);
    EXPECT_EQ(result.value, 0.0);
    EXPECT_TRUE(std::isfinite(glm::length(result.gradient)));
  }
  // Just off the edge the limit F -> 1/2 is approached (MATH.md s3) and stays finite.
  const auto near_edge = form_factor_gradient({0.5, -1e-9, 0}, kUp, wall);
  EXPECT_NEAR(near_edge.value, 0.5, 1e-6);
  EXPECT_TRUE(std::isfinite(glm::length(near_edge.gradient)));
  // A receiver point exactly at an emitter vertex after horizon clipping.
  const std::vector<dvec3> tilted = {{0, 0, 0}, {1, 0, 0}, {1, 1, 1}, {0, 1, 1}};
  const auto at_vertex = form_factor_gradient({0.5, 0, 0}, kUp, tilted);
  EXPECT_TRUE(std::isfinite(at_vertex.value));
  EXPECT_TRUE(std::isfinite(glm::length(at_vertex.gradient)));
}

TEST(FormFactorExtremes, EdgeSubtendingExactly90Degrees) {
  // p_0 . p_1 = 0 exactly: the printed edge matrix divides by zero here.
  const std::vector<dvec3> triangle = {{1, 0, 1}, {-1, 0, 1}, {0, 1, 1}};
  const auto c = glm::cross(triangle[1] - triangle[0], triangle[2] - triangle[0]);
  ASSERT_LT(c.z, 0.0);  // counter-clockwise about -z: faces the origin
  ASSERT_EQ(glm::dot(triangle[0], triangle[1]), 0.0);
  const auto robust = form_factor_gradient(dvec3(0), kUp, triangle);
  const auto general = form_factor_gradient(dvec3(0), kUp, as_contour(triangle));
  const dvec3 fd = central_difference([&](const dvec3& r) { return form_factor(r, kUp, triangle); },
                                      dvec3(0), 1e-6);
  expect_vec_near(robust.gradient, fd, 1e-8);
  expect_vec_near(general.gradient, fd, 1e-8);
}

// --- Invariances ---------------------------------------------------------------------------

TEST(FormFactorInvariance, TranslationRotationAndScale) {
  std::mt19937_64 rng(99);
  for (int trial = 0; trial < 500; ++trial) {
    const auto c = test::random_configuration(rng);
    const auto base = form_factor_gradient(c.point, c.normal, c.polygon);
    // Rotation about a random axis, then scale, then translation.
    const dvec3 axis = test::random_unit(rng);
    const double angle = 2 * kPi * std::uniform_real_distribution<double>(0, 1)(rng);
    const dmat3 rotation = dmat3(glm::rotate(glm::dmat4(1.0), angle, axis));
    const double scale = std::pow(10.0, std::uniform_real_distribution<double>(-3, 3)(rng));
    const dvec3 shift = 100.0 * test::random_unit(rng);
    const auto move = [&](const dvec3& v) { return scale * (rotation * v) + shift; };
    std::vector<dvec3> moved;
    for (const dvec3& v : c.polygon) moved.push_back(move(v));
    const auto result = form_factor_gradient(move(c.point), rotation * c.normal, moved);
    EXPECT_NEAR(result.value, base.value, 1e-10 + 1e-9 * base.value);
    // The gradient rotates with the scene and scales by 1/s.
    const dvec3 expected = rotation * base.gradient / scale;
    EXPECT_LE(glm::length(result.gradient - expected),
              1e-8 * glm::length(expected) + 1e-10 / scale);
  }
}

}  // namespace
}  // namespace radiosity

namespace radiosity {
namespace {

// --- Apparent vertices: the general Jacobian form on a depth-clipped emitter ----------

// The unit square emitter at z = 2 facing down, minus what a large occluder at
// z = 1 bounded by the line (point, direction) hides from r: the occluder covers
// the side where cross(direction, x - point).z > 0. The visible polygon's cut
// vertices are apparent, generated by an emitter edge and the occluder edge.
std::vector<ContourVertex> visible_part(const dvec3& r, const Line& occluder_edge) {
  const double z_emitter = 2, z_occluder = 1;
  const double stretch = (z_emitter - r.z) / (z_occluder - r.z);
  const dvec3 projected_point = r + (occluder_edge.point - r) * stretch;
  const dvec3 direction = occluder_edge.direction;  // parallel planes keep directions
  const auto side = [&](const dvec3& x) { return glm::cross(direction, x - projected_point).z; };
  const auto square = test::rectangle_facing_down(-.5, .5, -.5, .5, z_emitter);
  std::vector<ContourVertex> out;
  for (size_t i = 0; i < 4; ++i) {
    const dvec3 &a = square[i], &b = square[(i + 1) % 4];
    const double sa = side(a), sb = side(b);
    if (sa <= 0) out.push_back(ContourVertex::intrinsic(a));
    if ((sa <= 0) != (sb <= 0)) {
      const dvec3 at = a + (b - a) * (sa / (sa - sb));
      out.push_back(ContourVertex::apparent_vertex(at, Line{a, b - a}, occluder_edge));
    }
  }
  return out;
}

std::vector<dvec3> positions(const std::vector<ContourVertex>& contour) {
  std::vector<dvec3> out;
  for (const auto& v : contour) out.push_back(v.position);
  return out;
}

// Grazing normals make the horizon cut moving occluder edges, which exercises
// the Jacobian of horizon-clip points too.
TEST(FormFactorGradient, ApparentVerticesMatchFiniteDifferences) {
  std::mt19937_64 rng(4242);
  std::uniform_real_distribution<double> u(-1, 1);
  double worst = 0;
  int checked = 0;
  for (int trial = 0; trial < 2000; ++trial) {
    const double angle = kPi * u(rng);
    const Line edge{{0.3 * u(rng), 0.3 * u(rng), 1}, {std::cos(angle), std::sin(angle), 0}};
    const dvec3 r{0.4 * u(rng), 0.4 * u(rng), 0.5 * u(rng)};
    dvec3 n;
    do n = test::random_unit(rng);
    while (n.z < 0.2);
    const auto contour = visible_part(r, edge);
    if (contour.size() < 3) continue;
    bool has_apparent = false;
    for (const auto& v : contour) has_apparent |= v.apparent;
    if (!has_apparent) continue;
    const auto f = [&](const dvec3& x) {
      const auto c = visible_part(x, edge);
      return c.size() < 3 ? 0.0 : form_factor(x, n, positions(c));
    };
    const auto result = form_factor_gradient(r, n, contour);
    ASSERT_NEAR(result.value, f(r), 1e-14);
    const dvec3 fd = central_difference(f, r, 1e-6);
    const dvec3 fd_half = central_difference(f, r, 5e-7);
    if (result.value == 0.0) {  // the visible part lies below the horizon
      EXPECT_EQ(glm::length(result.gradient), 0.0);
      continue;
    }
    if (glm::length(fd - fd_half) > 1e-8 * glm::length(fd)) continue;  // at a D1/D2 event
    const double error = glm::length(result.gradient - fd) / glm::length(fd);
    worst = std::max(worst, error);
    ++checked;
    EXPECT_LT(error, 1e-6) << "trial " << trial << " r (" << r.x << ", " << r.y << ", " << r.z
                           << ") n (" << n.x << ", " << n.y << ", " << n.z << ")";
  }
  std::printf("apparent-vertex gradient vs FD: %d checked, worst relative error %.3g\n", checked,
              worst);
  EXPECT_GE(checked, 1000);
}

TEST(FormFactorGradient, TreatingApparentAsIntrinsicIsMeasurablyWrong) {
  // The check above can fail: the intrinsic Jacobian on the cut vertices is off.
  const Line edge{{0.1, 0, 1}, {0, 1, 0}};
  const dvec3 r(0.05, -0.1, 0), n(0, 0, 1);
  auto contour = visible_part(r, edge);
  const auto right = form_factor_gradient(r, n, contour);
  for (auto& v : contour) v.apparent = false;
  const auto wrong = form_factor_gradient(r, n, contour);
  EXPECT_GT(glm::length(wrong.gradient - right.gradient), 0.05 * glm::length(right.gradient));
}

}  // namespace
}  // namespace radiosity

namespace radiosity {
namespace {

TEST(FormFactorGradient, EdgeAlongTheHorizonStaysFinite) {
  // A visible piece with one vertex 1e-16 below the horizon (rounding): its
  // horizon crossing lies on an edge in the tangent plane (found by the
  // visibility tests).
  const dvec3 r(0.22486601452516758, -0.27562196932356731, 0);
  const dvec3 n(0.75645498309883608, -0.57279740863576667, 0.31571979222894847);
  const std::vector<ContourVertex> piece = {
      ContourVertex::intrinsic({-0.39369216399755957, 0.0098684423165902313, 2},
                               {0.026810438532263781, -0.18421105620156888, 0.64037816609558185}),
      ContourVertex::intrinsic({-0.36018376613390019, 0.054120727954533265, 2},
                               {0.037539461718629458, -0.170041957440387, 0.64037816609558185}),
      ContourVertex::intrinsic({-0.36018376613390024, 0.0098684423165902313, 2},
                               {0.037539461718629458, -0.18421105620156888, 0.64037816609558185}),
  };
  const auto result = form_factor_gradient(r, glm::normalize(n), piece);
  EXPECT_TRUE(std::isfinite(result.value));
  EXPECT_LT(glm::length(result.gradient), 1.0);
}

}  // namespace
}  // namespace radiosity
