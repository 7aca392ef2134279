// What a relight may change (reuse.h), and a relight through solve() with a
// SolveReuse: the lighting only, to what the kept links carry.
#include "core/solve/reuse.h"

#include <gtest/gtest.h>

#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// A floor under a lamp, both one-sided, and a two-sided shelf between them.
test::Arrays room(double lamp = 1.0, double floor_rho = 0.5, double shelf_emits = 0.0) {
  test::Arrays a;
  a.square(dvec3(0.0), 2.0, true, floor_rho, 0.0);
  a.square(dvec3(0.5, 0.5, 2.0), 1.0, false, 0.0, lamp);
  a.square(dvec3(0.8, 0.8, 1.0), 0.4, true, 0.3, shelf_emits, true);
  return a;
}

TEST(RelightRefusal, TheSameSceneAndOptionsRelight) {
  const SolveOptions options;
  EXPECT_EQ(relight_refusal(room().scene(), options, room().scene(), options),
            RelightRefusal::None);
}

TEST(RelightRefusal, LightingWithinWhatWasLinkedRelights) {
  const SolveOptions options;
  const Scene kept = room().scene();
  EXPECT_EQ(relight_refusal(kept, options, room(3.0).scene(), options),
            RelightRefusal::None);  // brighter lamp
  EXPECT_EQ(relight_refusal(kept, options, room(1.0, 0.9).scene(), options),
            RelightRefusal::None);  // paler floor
  EXPECT_EQ(relight_refusal(kept, options, room(1.0, 0.0).scene(), options),
            RelightRefusal::None);  // black floor
}

TEST(RelightRefusal, LimitsMayChange) {
  const SolveOptions kept_options;
  SolveOptions options;
  options.time_budget = 3.0;
  options.max_elements = 100;
  options.threads = 1;
  options.yield_to_interface = true;
  options.tolerance = 1e-4;
  options.max_iterations = 10;
  EXPECT_EQ(relight_refusal(room().scene(), kept_options, room().scene(), options),
            RelightRefusal::None);
}

TEST(RelightRefusal, OptionsTheLinksWereMadeWithMayNot) {
  const SolveOptions kept;
  const Scene scene = room().scene();
  auto refusal = [&](auto change) {
    SolveOptions options;
    change(options);
    return relight_refusal(scene, kept, scene, options);
  };
  EXPECT_EQ(refusal([](SolveOptions& o) { o.oracle = Oracle::Standard; }),
            RelightRefusal::OracleChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.quality = 0.7; }), RelightRefusal::QualityChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.rays = 64; }), RelightRefusal::VisibilityChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.faint_share = 0.0; }),
            RelightRefusal::VisibilityChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.dim_share = 0.0; }), RelightRefusal::LinkingChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.bounces = 3; }), RelightRefusal::FixedBounces);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.min_element_area = 1e-3; }),
            RelightRefusal::SmallestElementChanged);
  EXPECT_EQ(refusal([](SolveOptions& o) { o.leaf_links = SolveOptions::LeafLinks::All; }),
            RelightRefusal::LinkingChanged);
}

TEST(RelightRefusal, GeometryAndNewLightPathsMayNot) {
  const SolveOptions options;
  const Scene kept = room().scene();
  test::Arrays moved = room();
  moved.positions[2] += 1e-9;
  EXPECT_EQ(relight_refusal(kept, options, moved.scene(), options),
            RelightRefusal::GeometryChanged);
  test::Arrays more = room();
  more.square(dvec3(3.0, 0.0, 0.0), 1.0, true, 0.5, 0.0);
  EXPECT_EQ(relight_refusal(kept, options, more.scene(), options), RelightRefusal::GeometryChanged);
  EXPECT_EQ(relight_refusal(kept, options, room(1.0, 0.5, 2.0).scene(), options),
            RelightRefusal::NowEmits);
  EXPECT_EQ(relight_refusal(room(1.0, 0.0).scene(), options, room().scene(), options),
            RelightRefusal::NowReflects);
}

TEST(RelightRefusal, TakeLightingCopiesTheLightingOnly) {
  Scene kept = room().scene();
  const Scene brighter = room(4.0, 0.8).scene();
  take_lighting(kept, brighter);
  EXPECT_EQ(relight_refusal(kept, SolveOptions{}, brighter, SolveOptions{}), RelightRefusal::None);
  for (size_t i = 0; i < kept.patches.size(); ++i) {
    for (size_t s = 0; s < 2; ++s) {
      EXPECT_EQ(kept.patches[i].sides[s].emission, brighter.patches[i].sides[s].emission);
      EXPECT_EQ(kept.patches[i].sides[s].reflectance, brighter.patches[i].sides[s].reflectance);
    }
  }
  EXPECT_EQ(kept.emitted_power, brighter.emitted_power);
}

TEST(RelightRefusal, LightingScaleIsTheEmittedPowerRatio) {
  EXPECT_DOUBLE_EQ(lighting_scale(room().scene(), room(4.0).scene()), 4.0);
  EXPECT_DOUBLE_EQ(lighting_scale(room().scene(), room(1.0, 0.9).scene()), 1.0);
  // Emission added elsewhere counts as its power.
  const Scene two = room(1.0, 0.5, 1.0).scene();
  EXPECT_GT(lighting_scale(room().scene(), two), 1.0);
}

// Through solve(): the second solve relights (no link evaluated) and its
// radiance is the first's times the lamp's factor of 4, an exact scaling.
TEST(SolveReuse, RelightsAStrongerLampWithoutLinking) {
  SolveOptions options;
  options.quality = 0.5;
  SolveReuse reuse;
  const SolveResult first = solve(room().scene(), options, {}, {}, &reuse);
  ASSERT_TRUE(reuse.holds());
  EXPECT_FALSE(first.stats.reused);
  const SolveResult relit = solve(room(4.0).scene(), options, {}, {}, &reuse);
  EXPECT_TRUE(relit.stats.reused) << relight_refusal_name(relit.stats.reuse_refusal);
  EXPECT_EQ(relit.stats.link_cpu.samples_clear + relit.stats.link_cpu.samples_occluded, 0u);
  ASSERT_EQ(relit.mesh.positions, first.mesh.positions);
  for (size_t i = 0; i < first.mesh.radiance.size(); ++i)
    EXPECT_NEAR(relit.mesh.radiance[i], 4.0f * first.mesh.radiance[i], 1e-4);
}

}  // namespace
}  // namespace radiosity
