// Gather and push/pull (gather.h) against hand computations: what a receiver
// gathers through a link, what a split element hands its children, and that
// pushing light down the hierarchy neither makes nor loses energy.
#include "core/solve/gather.h"

#include <gtest/gtest.h>

#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// A floor (reflectance 0.5) lit by a lamp (radiance 2) through one link with
// form factor `f` at every sample, gathered at the floor's root.
struct OneLink {
  explicit OneLink(float f) : scene(arrays().scene()), h(scene) {
    Link l;
    l.receiver = h.root(0, 0);
    l.emitter = h.root(1, 0);
    l.form_factor.fill(f);
    links.push_back(l);
  }
  static test::Arrays arrays() {
    test::Arrays a;
    a.square(dvec3(0.0), 1.0, true, 0.5, 0.0);
    a.square(dvec3(0.0, 0.0, 1.0), 1.0, false, 0.0, 2.0);
    return a;
  }
  // The links grouped by receiver, and every element's radiance as the sources.
  LinkGather gather() {
    offset.assign(h.elements().size() + 1, 0);
    for (const Link& l : links) ++offset[static_cast<size_t>(l.receiver) + 1];
    for (size_t i = 1; i < offset.size(); ++i) offset[i] += offset[i - 1];
    order.resize(links.size());
    for (std::uint32_t i = 0; i < links.size(); ++i) order[i] = i;
    source.clear();
    for (const Element& e : h.elements()) source.push_back(e.radiance);
    return LinkGather{h, links, offset, order, source};
  }
  double push_pull_once() {
    const LinkGather g = gather();
    return push_pull(h, g, {}, {}, {}, {});
  }
  Scene scene;
  Hierarchy h;
  std::vector<Link> links;
  std::vector<std::uint32_t> offset, order;
  std::vector<Rgb> source;
};

TEST(Gather, AReceiverGathersFormFactorTimesRadiance) {
  OneLink s(0.2f);
  const SampleRgb h = s.gather()(s.h.root(0, 0));
  for (int k = 0; k < s.h.element(s.h.root(0, 0)).sample_count(); ++k)
    EXPECT_NEAR(h[static_cast<size_t>(k)].y, 0.2 * 2.0, 1e-7);
  // The lamp has no links: it gathers nothing.
  EXPECT_EQ(s.gather()(s.h.root(1, 0))[0], Rgb(0.0));
}

TEST(PushPull, ALeafBecomesEmissionPlusReflectedLight) {
  OneLink s(0.2f);
  const double residual = s.push_pull_once();
  EXPECT_GT(residual, 0.0);
  // L = L_e + rho H = 0 + 0.5 x 0.2 x 2.
  EXPECT_NEAR(s.h.element(s.h.root(0, 0)).radiance.x, 0.2, 1e-6);
  EXPECT_NEAR(s.h.element(s.h.root(1, 0)).radiance.x, 2.0, 1e-12);
  // Nothing changed since: the next iteration reports no change.
  EXPECT_NEAR(s.push_pull_once(), 0.0, 1e-9);
}

// A link at a split floor: its light is pushed to the four children, whose
// radiances average (by area) to what the parent gathered.
TEST(PushPull, LightGatheredAboveIsPushedToTheLeaves) {
  OneLink s(0.2f);
  const std::int32_t floor = s.h.root(0, 0);
  const std::int32_t first = s.h.subdivide(floor);
  s.push_pull_once();
  for (std::int32_t c = first; c < first + 4; ++c)
    EXPECT_NEAR(s.h.element(c).radiance.x, 0.2, 1e-6) << c;
  EXPECT_NEAR(s.h.element(floor).radiance.x, 0.2, 1e-6);
}

// Light varying over the parent (a gradient across its samples) reaches the
// children unevenly but with the same total.
TEST(PushToChildren, KeepsThePowerOfAVaryingGather) {
  OneLink s(0.0f);
  const std::int32_t floor = s.h.root(0, 0);
  s.h.subdivide(floor);
  const Element& parent = s.h.element(floor);
  SampleRgb total{};
  for (int k = 0; k < parent.sample_count(); ++k) total[static_cast<size_t>(k)] = Rgb(1.0 + k);
  const std::array<SampleRgb, 4> down = push_to_children(s.h, parent, total);
  double pushed = 0.0;
  for (int c = 0; c < 4; ++c) {
    const Element& child = s.h.element(parent.first_child + c);
    pushed += child.area * s.h.average(child, down[static_cast<size_t>(c)]).x;
  }
  const double expected = parent.area * s.h.average(parent, total).x;
  EXPECT_NEAR(pushed, expected, 1e-12 * expected);
  // Uneven: the children do not all receive the same.
  EXPECT_NE(s.h.average(s.h.element(parent.first_child), down[0]).x,
            s.h.average(s.h.element(parent.first_child + 2), down[2]).x);
}

TEST(GatheredAtLeaves, MatchesWhatPushPullUses) {
  OneLink s(0.25f);
  const std::int32_t first = s.h.subdivide(s.h.root(0, 0));
  const LinkGather g = s.gather();
  const std::vector<SampleRgb> leaves = gathered_at_leaves(s.h, g, {});
  std::vector<SampleRgb> used(s.h.elements().size());
  push_pull(s.h, g, {}, {}, {}, {}, &used);
  for (std::int32_t c = first; c < first + 4; ++c)
    for (size_t k = 0; k < kMaxSamples; ++k) {
      EXPECT_EQ(leaves[static_cast<size_t>(c)][k], used[static_cast<size_t>(c)][k]);
      EXPECT_NEAR(leaves[static_cast<size_t>(c)][k].x, 0.5, 1e-6);  // 0.25 x 2
    }
}

}  // namespace
}  // namespace radiosity
