// The refinement oracles on synthetic samples: the four cases of Section 6.3.4
// for the perceptual oracle, and the formulas of the standard and
// gradient-difference oracles on the same inputs.
#include "core/solve/oracle.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <vector>

namespace radiosity {
namespace {

// A unit square element in the z = 0 plane sampled at its corners and centre,
// with a radiosity profile B(x) and its gradient along x.
struct Profile {
  std::vector<dvec3> x = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {.5, .5, 0}};
  std::vector<double> b;
  std::vector<dvec3> g;

  Profile(const std::function<double(double)>& value, const std::function<double(double)>& slope) {
    for (const dvec3& p : x) {
      b.push_back(value(p.x));
      g.push_back({slope(p.x), 0, 0});
    }
  }
  double perceptual() const { return perceptual_criterion(x, b, g, {0, 0, 1}, std::sqrt(2.0)); }
  double geometry(Oracle oracle) const {
    return oracle_geometry(oracle, LinkSamples{x, b, g, {0, 0, 1}, 1.0, std::sqrt(2.0)});
  }
};

// A penumbra from 0.1 to 1 as a smoothstep over [x0, x0 + w].
Profile penumbra(double x0, double w) {
  const auto t = [=](double x) { return std::clamp((x - x0) / w, 0.0, 1.0); };
  return Profile(
      [=](double x) {
        const double s = t(x);
        return 0.1 + 0.9 * s * s * (3 - 2 * s);
      },
      [=](double x) {
        const double s = t(x);
        return (s > 0 && s < 1) ? 0.9 * 6 * s * (1 - s) / w : 0.0;
      });
}

TEST(PerceptualOracle, CaseA_UniformRegionIsNotRefined) {
  const Profile p([](double) { return 0.5; }, [](double) { return 0.0; });
  EXPECT_EQ(p.perceptual(), 0.0);
}

TEST(PerceptualOracle, CaseB_PenumbraBetweenSamplesActsLikeStandard) {
  // All samples outside the penumbra: flat tangents, different values.
  const Profile p = penumbra(0.2, 0.2);
  EXPECT_NEAR(p.perceptual(), 0.9, 1e-12);  // = B_max - B_min
  // A weak falloff must not make the gradients "collinear" and hide the edge.
  Profile weak = p;
  for (size_t i = 0; i < weak.g.size(); ++i) weak.g[i] = {1e-4, 1e-4 * static_cast<double>(i), 0};
  EXPECT_NEAR(weak.perceptual(), 0.9, 1e-3);
}

TEST(PerceptualOracle, CaseC_SampleInsidePenumbraIsRefinedMuchMore) {
  const Profile p = penumbra(0.4, 0.2);  // the centre lies mid-penumbra
  const double b_range = 0.9;
  EXPECT_GT(p.perceptual(), 2.5 * b_range);
  // The standard oracle only sees the value range.
  EXPECT_NEAR(p.geometry(Oracle::Standard), b_range, 1e-12);
}

TEST(PerceptualOracle, CaseD_LinearRampIsLeftToGouraud) {
  const Profile p([](double x) { return 0.1 + 0.9 * x; }, [](double) { return 0.9; });
  EXPECT_NEAR(p.perceptual(), 0.0, 1e-12);
  // Only the tangential part of a gradient counts (eq. 25): a normal component
  // changes nothing.
  Profile tilted = p;
  for (size_t i = 0; i < tilted.g.size(); ++i) tilted.g[i].z = 3.0 * static_cast<double>(i);
  EXPECT_NEAR(tilted.perceptual(), 0.0, 1e-12);
  // The standard oracle refines the ramp all the same.
  EXPECT_NEAR(p.geometry(Oracle::Standard), 0.9, 1e-12);
}

TEST(PerceptualOracle, CurvedProfileWithOpposedSlopesIsRefined) {
  // A highlight in the middle: slopes point inwards from both sides (Figure 31).
  const Profile p([](double x) { return 1 - 4 * (x - .5) * (x - .5); },
                  [](double x) { return -8 * (x - .5); });
  // k = 1 (opposed gradients), r from the tangent at x = 0 extrapolated to x = 1.
  EXPECT_NEAR(p.perceptual(), 4.0, 1e-12);
}

TEST(PerceptualOracle, ScalesLinearlyWithBrightness) {
  const Profile p = penumbra(0.4, 0.2);
  Profile brighter = p;
  for (double& b : brighter.b) b *= 50;
  for (dvec3& g : brighter.g) g *= 50;
  EXPECT_NEAR(brighter.perceptual(), 50 * p.perceptual(), 1e-9 * brighter.perceptual());
}

TEST(StandardOracle, IsValueRangeTimesArea) {
  const Profile p([](double x) { return 0.2 + 0.3 * x; }, [](double) { return 0.3; });
  EXPECT_NEAR(p.geometry(Oracle::Standard), 0.3, 1e-12);
  EXPECT_NEAR(oracle_geometry(Oracle::Standard, LinkSamples{p.x, p.b, {}, {0, 0, 1}, 2.5, 1.0}),
              0.75, 1e-12);
}

TEST(GradientOracle, IsLargestTangentialGradientDifferenceTimesArea) {
  // Eq. 19: the ramp has equal gradients: nothing to refine; the penumbra has
  // one sample with a steep gradient: its norm.
  const Profile ramp([](double x) { return 0.1 + 0.9 * x; }, [](double) { return 0.9; });
  EXPECT_NEAR(ramp.geometry(Oracle::Gradient), 0.0, 1e-12);
  const Profile p = penumbra(0.4, 0.2);
  EXPECT_NEAR(p.geometry(Oracle::Gradient), 0.9 * 6 * 0.25 / 0.2, 1e-12);
  // Normal components of the gradients are projected out (eq. 18).
  Profile tilted = ramp;
  for (size_t i = 0; i < tilted.g.size(); ++i) tilted.g[i].z = static_cast<double>(i);
  EXPECT_NEAR(tilted.geometry(Oracle::Gradient), 0.0, 1e-12);
}

// The visible-difference oracle on the same profiles: the error of the linear
// reconstruction (the mesh's Gouraud shading) from the samples.
TEST(NoticeableOracle, ALinearRampShowsNoError) {
  const Profile p([](double x) { return 0.1 + 0.9 * x; }, [](double) { return 0.9; });
  EXPECT_NEAR(p.geometry(Oracle::Noticeable), 0.0, 1e-12);
}

TEST(NoticeableOracle, ACurveIsJudgedWhereThePerceptualOraclesKIgnoresIt) {
  // Light falling off along a wall: every slope points the same way (k = 0 in
  // eq. 27, so the perceptual criterion is 0), yet the chord misses the curve.
  const Profile p([](double x) { return 0.2 + 0.3 * x + 0.3 * x * x; },
                  [](double x) { return 0.3 + 0.6 * x; });
  EXPECT_NEAR(p.perceptual(), 0.0, 1e-12);
  // Largest tangent miss: from x = 0 to x = 1, |0.2 + 0.3 - 0.8| = 0.3; half of it.
  EXPECT_NEAR(p.geometry(Oracle::Noticeable), 0.15, 1e-12);
}

TEST(NoticeableOracle, APenumbraBetweenSamplesCountsHalfItsStep) {
  const Profile p = penumbra(0.2, 0.2);  // flat tangents on both sides of the step
  EXPECT_NEAR(p.geometry(Oracle::Noticeable), 0.45, 1e-12);
}

TEST(NoticeableOracle, TangentsAtAContactClaimNoMoreThanTheLargestSample) {
  // A sample at a contact has a gradient without bound (MATH.md s3).
  Profile p([](double x) { return 0.01 + 0.02 * x; }, [](double) { return 0.02; });
  p.g[0] = {1e6, 0, 0};
  EXPECT_NEAR(p.geometry(Oracle::Noticeable), 0.03, 1e-12);
}

TEST(NoticeableOracle, ValuesAtAContactAreReachedByTheOtherSamplesTangents) {
  // The light rises towards a contact at x = 0 (sample 0 and 3, value-only,
  // listed last): the ramp of the others misses them by 0.5 - 0.2.
  Profile p([](double x) { return x == 0.0 ? 0.5 : 0.1 + 0.1 * x; }, [](double) { return 0.1; });
  std::vector<size_t> order = {1, 2, 4, 0, 3};
  Profile sorted = p;
  for (size_t i = 0; i < order.size(); ++i) {
    sorted.x[i] = p.x[order[i]], sorted.b[i] = p.b[order[i]], sorted.g[i] = {1e9, 0, 0};
    if (i < 3) sorted.g[i] = p.g[order[i]];
  }
  const LinkSamples samples{sorted.x, sorted.b, sorted.g, {0, 0, 1}, 1.0, std::sqrt(2.0), 0.0, 2};
  // Tangent at x = 1 (0.2, slope 0.1) reaches x = 0 at 0.1: misses 0.5 by 0.4.
  EXPECT_NEAR(oracle_geometry(Oracle::Noticeable, samples), 0.2, 1e-12);
  // Their own gradients (1e9 here) start no tangent: without the value-only
  // count they would claim the cap, the largest sample.
  LinkSamples all = samples;
  all.value_only = 0;
  EXPECT_NEAR(oracle_geometry(Oracle::Noticeable, all), 0.5, 1e-12);
}

TEST(NoticeableOracle, FadesForElementsNarrowerThanTheEyeResolves) {
  const Profile p = penumbra(0.2, 0.2);
  const auto geometry = [&](double area, double diameter, double resolvable) {
    return oracle_geometry(Oracle::Noticeable,
                           LinkSamples{p.x, p.b, p.g, {0, 0, 1}, area, diameter, resolvable});
  };
  // The unit square: width sqrt(2) x 1 / sqrt(2) = 1.
  EXPECT_NEAR(geometry(1.0, std::sqrt(2.0), 0.5), 0.45, 1e-12);
  EXPECT_NEAR(geometry(1.0, std::sqrt(2.0), 4.0), 0.45 / 4.0, 1e-12);
  // A sliver as long but a tenth as wide is a tenth as visible.
  EXPECT_NEAR(geometry(0.1, std::sqrt(2.0), 1.0), 0.045, 1e-12);
}

TEST(NoticeableOracle, ThresholdsAreJustNoticeableDifferencesAtTheReceiver) {
  // Weber: one JND is 2 % of the receiver's radiance, above a floor of a fifth
  // of the adaptation level in the dark.
  EXPECT_NEAR(oracle_reference(Oracle::Noticeable, 1.0, 3.0), 0.02 * 3.2, 1e-15);
  EXPECT_NEAR(oracle_reference(Oracle::Noticeable, 1.0, 0.0), 0.02 * 0.2, 1e-15);
  // Scaling every radiance scales the reference: decisions do not change.
  EXPECT_NEAR(oracle_reference(Oracle::Noticeable, 7.0, 21.0),
              7.0 * oracle_reference(Oracle::Noticeable, 1.0, 3.0), 1e-15);
  // The source's oracles stay relative to the adaptation level alone.
  EXPECT_EQ(oracle_reference(Oracle::Perceptual, 0.5, 3.0), 0.5);
}

TEST(Oracle, NamesRoundTrip) {
  for (Oracle o : {Oracle::Standard, Oracle::Perceptual, Oracle::Gradient, Oracle::Noticeable}) {
    EXPECT_EQ(parse_oracle(oracle_name(o)), o);
  }
  EXPECT_FALSE(parse_oracle("bf").has_value());
}

TEST(Oracle, ScaleMakesThresholdsRelative) {
  // Doubling every length and halving every radiance leaves each criterion's
  // relative value unchanged: check the scale's units.
  const double area = 80, radiance = 0.06;
  EXPECT_NEAR(oracle_scale(Oracle::Standard, 2 * radiance, 4 * area) /
                  oracle_scale(Oracle::Standard, radiance, area),
              8.0, 1e-12);
  EXPECT_NEAR(oracle_scale(Oracle::Perceptual, 2 * radiance, 4 * area) /
                  oracle_scale(Oracle::Perceptual, radiance, area),
              2.0, 1e-12);
  EXPECT_NEAR(oracle_scale(Oracle::Gradient, 2 * radiance, 4 * area) /
                  oracle_scale(Oracle::Gradient, radiance, area),
              4.0, 1e-12);
}

}  // namespace
}  // namespace radiosity
