// Which samples exact visibility leaves to shadow rays (faint_samples.h),
// against hand computations on a made-up ray pass over three squares.
#include "core/solve/faint_samples.h"

#include <gtest/gtest.h>

#include "core/hierarchy/hierarchy.h"
#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// A lamp (L_e 2, reflects nothing), a square B (rho 0.5) that gathered 1 and
// a square C (rho 0.5) that gathered 0.1: they send 2, 0.5 and 0.05.
struct ThreeSquares {
  ThreeSquares() : scene(arrays().scene()), h(scene) {
    for (std::uint32_t p = 0; p < 3; ++p) id[p] = h.root(p, 0);
    pass.complete = true;
    pass.gathered.assign(h.elements().size(), Rgb(0.0));
    pass.gathered[static_cast<std::size_t>(id[B])] = Rgb(1.0);
    pass.gathered[static_cast<std::size_t>(id[C])] = Rgb(0.1);
  }
  static test::Arrays arrays() {
    test::Arrays a;
    a.square(dvec3(0.0, 0.0, 2.0), 1.0, false, 0.0, 2.0);
    a.square(dvec3(0.0, 0.0, 0.0), 1.0, true, 0.5, 0.0);
    a.square(dvec3(2.0, 0.0, 0.0), 1.0, true, 0.5, 0.0);
    return a;
  }
  enum Square { Lamp, B, C };
  Scene scene;
  Hierarchy h;
  std::int32_t id[3] = {};
  RayPass pass;
};

TEST(FaintSamples, AreThoseWhoseUnoccludedLightIsBelowTheShareOfTheSidesGather) {
  ThreeSquares s;
  const FaintSamples faint(s.h, s.pass, 0.1);  // faint below 0.1 on B, 0.01 on C
  ASSERT_FALSE(faint.empty());
  using T = ThreeSquares;
  EXPECT_TRUE(faint.faint(s.id[T::B], s.id[T::Lamp], 0.049));   // 2 x 0.049 = 0.098
  EXPECT_FALSE(faint.faint(s.id[T::B], s.id[T::Lamp], 0.051));  // 0.102
  EXPECT_TRUE(faint.faint(s.id[T::C], s.id[T::B], 0.019));      // 0.5 x 0.019 = 0.0095
  EXPECT_FALSE(faint.faint(s.id[T::C], s.id[T::B], 0.021));     // 0.0105
  EXPECT_TRUE(faint.faint(s.id[T::B], s.id[T::C], 1.0));        // 0.05 < 0.1
  // A side that gathered nothing finds no light faint.
  EXPECT_FALSE(faint.faint(s.id[T::Lamp], s.id[T::C], 1e-9));
}

TEST(FaintSamples, NoneWithoutAShareOrACompletePass) {
  ThreeSquares s;
  EXPECT_TRUE(FaintSamples(s.h, s.pass, 0.0).empty());
  s.pass.complete = false;
  EXPECT_TRUE(FaintSamples(s.h, s.pass, 0.1).empty());
}

}  // namespace
}  // namespace radiosity
