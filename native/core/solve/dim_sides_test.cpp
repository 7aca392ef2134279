// Which sides are too dim to link, and what they and the linked sides gather
// by the ray pass's rays (dim_sides.h), against hand computations on a made-up
// ray pass over four squares.
#include "core/solve/dim_sides.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// A lamp (reflects nothing) and three unit squares that reflect: B lit
// directly and bright, C and D lit only by what B reflects, dim. Each side
// traced four rays.
struct FourSquares {
  FourSquares() : scene(arrays().scene()), h(scene) {
    for (std::uint32_t p = 0; p < 4; ++p) id[p] = h.root(p, 0);
    const std::size_t count = h.elements().size();
    pass.rays = 4;
    pass.complete = true;
    pass.gathered.assign(count, Rgb(0.0));
    pass.unlit.assign(count, 0);
    pass.lighting_rays.assign(count, 0);
    pass.met.assign(count * 4, kNone);
    pass.gathered[at(B)] = Rgb(1.0);
    pass.gathered[at(C)] = Rgb(0.01);
    pass.gathered[at(D)] = Rgb(0.015);
    pass.lighting_rays[at(B)] = 4;
    rays(B, {id[C], id[Lamp], kNone, id[D]});
    rays(C, {id[B], id[D], kNone, id[B]});
    rays(D, {id[C], id[C], id[B], kNone});
  }
  static test::Arrays arrays() {
    test::Arrays a;
    a.square(dvec3(0.0, 0.0, 2.0), 1.0, false, 0.0, 2.0);  // the lamp
    for (int k = 0; k < 3; ++k) a.square(dvec3(2.0 * k, 0.0, 0.0), 1.0, true, 0.5, 0.0);
    return a;
  }
  enum Square { Lamp, B, C, D };
  std::size_t at(Square s) const { return static_cast<std::size_t>(id[s]); }
  void rays(Square s, std::vector<std::int32_t> met) {
    for (std::size_t k = 0; k < met.size(); ++k) pass.met[at(s) * 4 + k] = met[k];
  }

  Scene scene;
  Hierarchy h;
  std::int32_t id[4] = {};
  RayPass pass;
};

TEST(DimSides, AreTheSidesWithoutDirectLightBelowTheShareOfTheMean) {
  FourSquares s;
  // The mean over the sides that reflect: (1 + 0.01 + 0.015) / 3 = 0.342.
  const DimSides none(s.h, s.pass, 0.02);  // below 0.0068: neither C nor D
  EXPECT_TRUE(none.empty());
  const DimSides two(s.h, s.pass, 0.05);  // below 0.0171: both
  EXPECT_EQ(two.count(), 2u);
  EXPECT_EQ(two.dim()[s.at(FourSquares::C)], 1);
  EXPECT_EQ(two.dim()[s.at(FourSquares::D)], 1);
  EXPECT_EQ(two.dim()[s.at(FourSquares::B)], 0);
  // A side a ray brought direct light to is linked however dark it is: B at
  // 0.001, below the mean (0.001 + 0.01 + 0.05) / 3 = 0.0203 as C is.
  s.pass.gathered[s.at(FourSquares::B)] = Rgb(0.001);
  s.pass.gathered[s.at(FourSquares::D)] = Rgb(0.05);
  const DimSides all(s.h, s.pass, 1.0);
  EXPECT_EQ(all.count(), 1u);
  EXPECT_EQ(all.dim()[s.at(FourSquares::B)], 0);
  EXPECT_EQ(all.dim()[s.at(FourSquares::C)], 1);
  // Nothing without a complete pass.
  s.pass.complete = false;
  EXPECT_TRUE(DimSides(s.h, s.pass, 1.0).empty());
}

TEST(DimSides, GatherTheMeanOfWhatTheirRaysMet) {
  FourSquares s;
  const DimSides dim(s.h, s.pass, 0.05);
  s.h.element(s.id[FourSquares::Lamp]).radiance = Rgb(2.0);
  s.h.element(s.id[FourSquares::B]).radiance = Rgb(0.4);
  s.h.element(s.id[FourSquares::C]).radiance = Rgb(0.1);
  s.h.element(s.id[FourSquares::D]).radiance = Rgb(0.2, 0.3, 0.4);
  std::vector<Rgb> light;
  dim.gather(s.h, light);
  ASSERT_EQ(light.size(), s.h.elements().size());
  // C met B, D, nothing, B; D met C, C, B, nothing: every side counts.
  const Rgb c = (Rgb(0.4) + Rgb(0.2, 0.3, 0.4) + Rgb(0.4)) / 4.0;
  const Rgb d = (Rgb(0.1) + Rgb(0.1) + Rgb(0.4)) / 4.0;
  // B is linked: it gathers by rays from the dim sides only (C, D), not the
  // lamp its second ray met: that comes through its links.
  const Rgb b = (Rgb(0.1) + Rgb(0.2, 0.3, 0.4)) / 4.0;
  for (int k = 0; k < 3; ++k) {
    EXPECT_DOUBLE_EQ(light[s.at(FourSquares::C)][k], c[k]);
    EXPECT_DOUBLE_EQ(light[s.at(FourSquares::D)][k], d[k]);
    EXPECT_DOUBLE_EQ(light[s.at(FourSquares::B)][k], b[k]);
    EXPECT_EQ(light[s.at(FourSquares::Lamp)][k], 0.0);
  }
  // The share of each side's rays that went to a dim side: for the energy
  // balance, light that leaves by rays.
  EXPECT_FLOAT_EQ(dim.share_to_dim()[s.at(FourSquares::B)], 0.5f);
  EXPECT_FLOAT_EQ(dim.share_to_dim()[s.at(FourSquares::C)], 0.25f);
  EXPECT_FLOAT_EQ(dim.share_to_dim()[s.at(FourSquares::D)], 0.5f);
}

}  // namespace
}  // namespace radiosity
