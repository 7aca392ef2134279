// The refinement policy (refine.h): which end of a link is split, what a split
// does to the links, the element budget, and which links a split receiver
// hands down to its children.
#include "core/solve/refine.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// A lit floor square (side `floor`, reflectance 0.5) under an emitting square
// (side `lamp`, radiance 1) at height `height`, facing each other; both one-sided.
struct FloorAndLamp {
  FloorAndLamp(double floor, double lamp, double height)
      : scene(arrays(floor, lamp, height).scene()), h(scene) {}
  static test::Arrays arrays(double floor, double lamp, double height) {
    test::Arrays a;
    a.square(dvec3(0.0), floor, true, 0.5, 0.0);
    a.square(dvec3(0.0, 0.0, height), lamp, false, 0.0, 1.0);
    return a;
  }
  std::int32_t floor() const { return h.root(0, 0); }
  std::int32_t lamp() const { return h.root(1, 0); }
  Link link(float oracle) const {
    Link l;
    l.receiver = floor();
    l.emitter = lamp();
    l.oracle = oracle;
    return l;
  }
  Scene scene;
  Hierarchy h;
};

// The criterion is brightness (rho_p L_q = 0.5 here) / reference x oracle.
TEST(ChooseSplit, SplitsOnlyAboveTheThreshold) {
  const FloorAndLamp s(1.0, 1.0, 1.0);
  const RefineLimits limits{1e-6, {}};
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 0.49, DecisionScale{Oracle::Standard, 1.0}, limits),
            Split::Receiver);
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 0.51, DecisionScale{Oracle::Standard, 1.0}, limits),
            Split::None);
  // Twice the reference brightness halves the criterion.
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 0.3, DecisionScale{Oracle::Standard, 2.0}, limits),
            Split::None);
  // A link from an emitter that sends nothing is never worth splitting.
  FloorAndLamp dark(1.0, 1.0, 1.0);
  dark.h.element(dark.lamp()).radiance = Rgb(0.0);
  EXPECT_EQ(
      choose_split(dark.h, dark.link(1e6f), 1e-9, DecisionScale{Oracle::Standard, 1.0}, limits),
      Split::None);
}

TEST(ChooseSplit, SplitsTheLargerEnd) {
  const RefineLimits limits{1e-6, {}};
  const FloorAndLamp big_floor(1.0, 0.5, 1.0);
  EXPECT_EQ(choose_split(big_floor.h, big_floor.link(1.0f), 0.1,
                         DecisionScale{Oracle::Standard, 1.0}, limits),
            Split::Receiver);
  const FloorAndLamp big_lamp(0.5, 1.0, 1.0);
  EXPECT_EQ(choose_split(big_lamp.h, big_lamp.link(1.0f), 0.1, DecisionScale{Oracle::Standard, 1.0},
                         limits),
            Split::Emitter);
}

TEST(ChooseSplit, NoticeableIsRelativeToTheReceiversRadiance) {
  // brightness 0.5 x oracle 1 over one JND at the receiver: 0.02 (L_p + 0.2 x 1).
  FloorAndLamp s(1.0, 1.0, 1.0);
  const DecisionScale scale{Oracle::Noticeable, 1.0};
  const RefineLimits limits{1e-6, {}};
  s.h.element(s.floor()).radiance = Rgb(0.8);  // 0.5 / 0.02 = 25 JND
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 24.0, scale, limits), Split::Receiver);
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 26.0, scale, limits), Split::None);
  // The same error on a receiver four times brighter is four times less visible.
  s.h.element(s.floor()).radiance = Rgb(3.8);
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 6.0, scale, limits), Split::Receiver);
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 6.5, scale, limits), Split::None);
}

TEST(ChooseSplit, NoticeableSplitsAnUnevenEmitterItsReceiverSeesEvenly) {
  // A reflecting square (rho 0.5) above the floor, already split, whose link
  // shows no error at the floor's samples (oracle 0, F = 0.2 at each).
  test::Arrays a;
  a.square(dvec3(0.0), 1.0, true, 0.5, 0.0);
  a.square(dvec3(0.0, 0.0, 1.0), 1.0, false, 0.5, 0.0);
  a.square(dvec3(5.0, 0.0, 1.0), 0.1, false, 0.0, 1.0);  // a scene needs a light
  const Scene scene = a.scene();
  Hierarchy h(scene);
  const std::int32_t floor = h.root(0, 0), ceiling = h.root(1, 0);
  const std::int32_t first = h.subdivide(ceiling);
  h.element(floor).radiance = Rgb(0.8);  // one JND there: 0.02 (0.8 + 0.2 x 1)
  Link link;
  link.receiver = floor;
  link.emitter = ceiling;
  link.form_factor.fill(0.2f);
  const DecisionScale noticeable{Oracle::Noticeable, 1.0};
  const RefineLimits limits{1e-6, {}};
  const auto parts = [&](double a0, double a1, double a2, double a3) {
    const double r[4] = {a0, a1, a2, a3};
    for (int c = 0; c < 4; ++c) h.element(first + c).radiance = Rgb(r[c]);
    h.element(ceiling).radiance = Rgb(0.25 * (a0 + a1 + a2 + a3));
  };
  // Parts 0.2 to 0.6: 0.5 x 0.2 x 0.4 = 0.04, two JND.
  parts(0.2, 0.6, 0.4, 0.4);
  EXPECT_EQ(choose_split(h, link, 1.5, noticeable, limits), Split::Emitter);
  EXPECT_EQ(choose_split(h, link, 2.5, noticeable, limits), Split::None);
  EXPECT_EQ(choose_split(h, link, 1.5, DecisionScale{Oracle::Standard, 1.0}, limits), Split::None);
  // An even emitter sends the right radiance whatever part the receiver sees.
  parts(0.4, 0.4, 0.4, 0.4);
  EXPECT_EQ(choose_split(h, link, 1e-3, noticeable, limits), Split::None);
}

TEST(ChooseSplit, NothingBelowTheSmallestElement) {
  const FloorAndLamp s(1.0, 0.5, 1.0);
  // The floor's children would be 0.25, the lamp's 0.0625 (in the input's
  // units; the limits are areas in the solver's frame, scene.h).
  const double to_frame = s.h.scene().frame.scale * s.h.scene().frame.scale;
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 0.1, DecisionScale{Oracle::Standard, 1.0},
                         RefineLimits{0.3 * to_frame, {}}),
            Split::None);
  EXPECT_EQ(choose_split(s.h, s.link(1.0f), 0.1, DecisionScale{Oracle::Standard, 1.0},
                         RefineLimits{0.2 * to_frame, {}}),
            Split::Receiver);
}

TEST(SplitLinks, ASplitLinkBecomesFourLinksToTheChildrenInOrder) {
  FloorAndLamp s(1.0, 1.0, 1.0);
  const std::vector<Link> links = {s.link(1.0f), s.link(0.0f)};
  const std::vector<Split> decision = {Split::Receiver, Split::None};
  const size_t before = s.h.elements().size();
  const SplitLinks round = split_links(s.h, links, decision, RefineLimits{1e-6, {}});
  EXPECT_FALSE(round.budget_hit);
  EXPECT_EQ(s.h.elements().size(), before + 4);
  ASSERT_EQ(round.fresh.size(), 4u);
  const std::int32_t first = s.h.element(s.floor()).first_child;
  for (int c = 0; c < 4; ++c) {
    EXPECT_EQ(round.fresh[static_cast<size_t>(c)].receiver, first + c);
    EXPECT_EQ(round.fresh[static_cast<size_t>(c)].emitter, s.lamp());
  }
  ASSERT_EQ(round.kept.size(), 1u);
  EXPECT_EQ(round.kept[0].oracle, 0.0f);
  // The children tile their parent.
  double area = 0.0;
  for (int c = 0; c < 4; ++c) area += s.h.element(first + c).area;
  EXPECT_NEAR(area, s.h.element(s.floor()).area, 1e-12);
}

TEST(SplitLinks, TheElementBudgetRefusesNewElementsOnly) {
  FloorAndLamp s(1.0, 1.0, 1.0);
  const std::vector<Link> links = {s.link(1.0f), s.link(1.0f)};
  const std::vector<Split> decision = {Split::Receiver, Split::Receiver};
  const size_t before = s.h.elements().size();
  // Room for one split: the first makes four elements, the second link's
  // receiver is then split already and costs nothing.
  const SplitLinks round = split_links(s.h, links, decision, RefineLimits{1e-6, before + 4});
  EXPECT_FALSE(round.budget_hit);
  EXPECT_EQ(round.fresh.size(), 8u);
  EXPECT_EQ(s.h.elements().size(), before + 4);

  FloorAndLamp full(1.0, 1.0, 1.0);
  const SplitLinks refused =
      split_links(full.h, links, decision, RefineLimits{1e-6, full.h.elements().size() + 3});
  EXPECT_TRUE(refused.budget_hit);
  EXPECT_TRUE(refused.fresh.empty());
  EXPECT_EQ(refused.kept.size(), 2u);
  EXPECT_TRUE(full.h.element(full.floor()).is_leaf());
}

// A link whose receiver is split elsewhere: "near" hands it down only when
// the emitter is within twice the receiver's radius, "all" always, "none" never.
TEST(HandDownLinks, NearFieldLinksFollowASplitReceiver) {
  for (const double height : {0.5, 100.0}) {
    for (const auto mode : {SolveOptions::LeafLinks::None, SolveOptions::LeafLinks::Near,
                            SolveOptions::LeafLinks::All}) {
      FloorAndLamp s(1.0, 1.0, height);
      s.h.subdivide(s.floor());
      SplitLinks links;
      links.kept = {s.link(0.0f)};
      hand_down_links(s.h, mode, links);
      const bool near = near_field(s.h, s.link(0.0f), true);
      EXPECT_EQ(near, height < 1.0);
      const bool moved =
          mode == SolveOptions::LeafLinks::All || (mode == SolveOptions::LeafLinks::Near && near);
      EXPECT_EQ(links.kept.size(), moved ? 0u : 1u) << height;
      ASSERT_EQ(links.fresh.size(), moved ? 4u : 0u) << height;
      for (const Link& l : links.fresh) {
        EXPECT_EQ(s.h.element(l.receiver).parent, s.floor());
        EXPECT_EQ(l.emitter, s.lamp());
      }
    }
  }
}

TEST(AdaptationRadiance, ScalesWithTheSolution) {
  FloorAndLamp s(1.0, 1.0, 1.0);
  const double unlit = adaptation_radiance(s.h);
  EXPECT_GT(unlit, 0.0);
  for (Element& e : s.h.elements()) e.radiance *= 2.0;
  EXPECT_NEAR(adaptation_radiance(s.h), 2.0 * unlit, 1e-12 * unlit);
  // A dark scene falls back to the emitted power over the area.
  for (Element& e : s.h.elements()) e.radiance = Rgb(0.0);
  EXPECT_DOUBLE_EQ(adaptation_radiance(s.h), s.scene.reference_radiance());
}

}  // namespace
}  // namespace radiosity
