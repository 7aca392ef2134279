// The cluster tree and the cluster links: structure, facing, that a far
// cluster sends what its sides would through their own exact links and a
// receiving cluster gives each side its own light, the cluster criterion, and
// that splitting a link keeps what it covered.
#include "core/solve/cluster_links.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <set>

#include "core/geometry/form_factor.h"
#include "core/hierarchy/cluster_tree.h"
#include "core/scene/test_scenes.h"
#include "core/solve/link_transport.h"
#include "radiosity/scene.h"

namespace radiosity {
namespace {

using test::Arrays;

// A grid of n x n small squares at height z, facing up or down.
void grid(Arrays& a, double z, int n, bool up, double rho, double emit, bool both_sides = false) {
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      a.square(dvec3(0.3 * i, 0.3 * j, z), 0.2, up, rho, emit, both_sides);
}

// A criterion by distance alone.
ClusterCriterion by_separation(double separation) {
  ClusterCriterion c;
  c.separation = separation;
  c.threshold = std::numeric_limits<double>::infinity();
  return c;
}

// Every pair of top-level elements a link covers (its clusters' sides).
std::set<std::pair<std::int32_t, std::int32_t>> covered(const ClusterTree& tree,
                                                        const InitialLinks& links) {
  std::set<std::pair<std::int32_t, std::int32_t>> pairs;
  for (const ClusterLink& l : links.clusters) {
    const ClusterNode& x = tree.node(l.receiver);
    const ClusterNode& y = tree.node(l.emitter);
    for (std::uint32_t i = x.first; i < x.first + x.count; ++i)
      for (std::uint32_t j = y.first; j < y.first + y.count; ++j)
        EXPECT_TRUE(pairs.emplace(tree.sides()[i], tree.sides()[j]).second) << "covered twice";
  }
  for (const Link& l : links.elements)
    EXPECT_TRUE(pairs.emplace(l.receiver, l.emitter).second) << "covered twice";
  return pairs;
}

// A scene with its hierarchy, cluster tree and occluders, linked at `separation`.
struct Linked {
  explicit Linked(const Arrays& a)
      : scene(a.scene()), h(scene), tree(h), occluders(make_scene_occluders(scene)) {}
  InitialLinks link(double separation) const { return link(by_separation(separation)); }
  InitialLinks link(const ClusterCriterion& c) const {
    return link_clusters(tree, h, *occluders.rays, c, {});
  }
  // The far light at every top-level element's samples, with `radiance` per element.
  std::vector<SampleRgb> far_light(const InitialLinks& links,
                                   const std::vector<Rgb>& radiance) const {
    std::vector<ClusterLink> sorted = links.clusters;
    sort_by_receiver(sorted);
    std::vector<SampleRgb> gathered;
    ClusterGather gather;
    gather(tree, sorted, h, radiance, gathered);
    return gathered;
  }
  Scene scene;
  Hierarchy h;
  ClusterTree tree;
  SceneOccluders occluders;
};

TEST(ClusterTree, EverySideInOneLeafAndNodesHoldTheirSides) {
  Arrays a;
  grid(a, 0.0, 5, true, 0.5, 0.0, true);
  grid(a, 3.0, 4, false, 0.5, 1.0);
  const Scene scene = a.scene();
  const Hierarchy h(scene);
  const ClusterTree tree(h);
  std::vector<int> seen(h.elements().size(), 0);
  for (const ClusterNode& node : tree.nodes()) {
    if (node.is_leaf()) {
      ASSERT_EQ(node.count, 1u);
      ++seen[static_cast<size_t>(tree.sides()[node.first])];
      continue;
    }
    // Its sphere holds every corner of its sides.
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
      dvec3 c[4];
      const int n = h.corners(h.element(tree.sides()[i]), c);
      for (int k = 0; k < n; ++k)
        EXPECT_LE(glm::length(c[k] - node.centre), node.radius * (1 + 1e-12));
    }
    const ClusterNode& l = tree.node(node.child[0]);
    const ClusterNode& r = tree.node(node.child[1]);
    EXPECT_EQ(l.first, node.first);
    EXPECT_EQ(l.count + r.count, node.count);
    for (const ClusterNode* c : {&l, &r}) {
      EXPECT_LE(std::acos(std::clamp(glm::dot(c->axis, node.axis), -1.0, 1.0)) + c->spread,
                node.spread + 1e-9);
    }
  }
  // 25 two-sided squares (50 sides) and 16 one-sided lights.
  int sides = 0;
  for (int s : seen) {
    EXPECT_LE(s, 1);
    sides += s;
  }
  EXPECT_EQ(sides, 66);
  // Sides facing up and down are split apart at the top.
  const ClusterNode& root = tree.node(tree.root());
  EXPECT_GT(root.spread, 3.0);
  EXPECT_LT(tree.node(root.child[0]).spread, 1e-9);
}

TEST(ClusterLinks, FarGridsShareLinksNearOnesDoNot) {
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  grid(a, 20.0, 4, false, 0.5, 1.0);
  const Linked linked(a);
  const ClusterTree& tree = linked.tree;
  const InitialLinks far = linked.link(2.0);
  EXPECT_GT(far.clusters.size(), 0u);
  // The upper grid receives from the lower one through a few cluster links
  // ending on clusters, not one per side (the lower grid receives from the
  // emitting one through face links: distance alone never links emitters).
  EXPECT_LT(far.clusters.size(), 4u);
  for (const ClusterLink& l : far.clusters) {
    EXPECT_FALSE(tree.node(l.receiver).is_leaf());
    EXPECT_GT(l.visibility, 0.0f);
    EXPECT_LE(l.visibility, 1.0f);
  }
  EXPECT_EQ(far.elements.size(), 16u * 16);
  // Every pair that can exchange light is covered once, by one link or another.
  EXPECT_EQ(covered(tree, far).size(), 2u * 16 * 16);
  // Infinitely demanding separation: only pairs of sides.
  const InitialLinks pairs = linked.link(std::numeric_limits<double>::infinity());
  EXPECT_EQ(pairs.clusters.size(), 0u);
  EXPECT_EQ(pairs.elements.size(), 2u * 16 * 16);  // each grid lights the other (both reflect)
}

// The far light at each receiving square's samples against the sum of the
// exact point-to-polygon form factors of the lit squares (radiance 2) there,
// for two 4 x 4 grids `height` apart (the upper one moved by `offset` along
// x) linked at `separation`; the largest relative error over the samples.
double far_light_error(double height, double separation, double offset = 0.0) {
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j)
      a.square(dvec3(offset + 0.3 * i, 0.3 * j, height), 0.2, false, 0.5, 0.0);
  a.square(dvec3(0.0, 0.0, -50.0), 0.1, false, 0.0,
           1.0);  // a scene needs an emitter: this one faces away
  const Linked linked(a);
  const Hierarchy& h = linked.h;
  const InitialLinks links = linked.link(separation);
  EXPECT_GT(links.clusters.size(), 0u);
  // Pairs the walk left to face links are not part of the cluster light.
  const auto face_linked = [&](std::int32_t receiver, std::int32_t emitter) {
    for (const Link& l : links.elements)
      if (l.receiver == receiver && l.emitter == emitter) return true;
    return false;
  };
  std::vector<Rgb> radiance(h.elements().size(), Rgb(0.0));
  for (std::uint32_t q = 16; q < 32; ++q) radiance[static_cast<size_t>(h.root(q, 0))] = Rgb(2.0);
  const std::vector<SampleRgb> gathered = linked.far_light(links, radiance);
  double worst = 0.0;
  for (std::uint32_t r = 0; r < 16; ++r) {
    const Element& receiver = h.element(h.root(r, 0));
    dvec3 at[kMaxSamples];
    const int samples = h.samples(receiver, at);
    for (int s = 0; s < samples; ++s) {
      double exact = 0.0;
      for (std::uint32_t q = 16; q < 32; ++q) {
        if (face_linked(h.root(r, 0), h.root(q, 0))) continue;
        dvec3 c[4];
        const int n = h.corners(h.element(h.root(q, 0)), c);
        exact += 2.0 * form_factor(at[s], h.normal(receiver),
                                   std::span<const dvec3>(c, static_cast<size_t>(n)));
      }
      const double got = gathered[static_cast<size_t>(h.root(r, 0))][static_cast<size_t>(s)].x;
      worst = std::max(worst, std::abs(got - exact) / exact);
    }
  }
  return worst;
}

TEST(ClusterLinks, FarLightMatchesThePointFormFactorsOfItsSides) {
  // 20 apart: within 1 % at every sample of every receiver.
  EXPECT_LT(far_light_error(20.0, 2.0), 0.01);
}

TEST(ClusterLinks, AReceivingClusterGivesEachSideItsOwnLight) {
  // The lit grid 3 up and 3 aside (the grids are 1.1 across, one link between
  // them): the light changes by half over the receiving grid. Its
  // first-order change keeps every sample within 11 % (the second-order rest
  // at this distance), where the light of the cluster's centre would be off
  // by 46 % (computed by quadrature while writing this test).
  EXPECT_LT(far_light_error(3.0, 2.0, 3.0), 0.11);
}

TEST(ClusterLinks, LightStraightFromEmittersGoesThroughFaceLinks) {
  // The same grids with the upper one emitting: far apart as they are, every
  // pair is a face link (exact visibility at the receivers' samples).
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  grid(a, 20.0, 4, false, 0.0, 2.0);
  const Linked linked(a);
  const InitialLinks links = linked.link(2.0);
  EXPECT_EQ(links.clusters.size(), 0u);
  EXPECT_EQ(links.elements.size(), 16u * 16u);
}

TEST(ClusterLinks, SidesHiddenFromTheLightsGetNoLinksFromThem) {
  // A two-sided square far above a grid of reflecting squares, and a
  // one-sided one hidden right above it: the square's top faces away from the
  // grid, the hidden one is behind it. Neither may receive from the grid
  // through a cluster link (pairs of sides are left to the exact link
  // evaluation).
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  const dvec3 lo(0.0, 0.0, 10.0);
  a.square(lo, 1.0, false, 0.5, 0.0, true);                     // bottom, two-sided
  a.square(lo + dvec3(0.25, 0.25, 0.5), 0.5, false, 0.5, 0.0);  // hidden, facing down
  a.square(dvec3(0.0, 0.0, -50.0), 0.1, false, 0.0,
           1.0);  // a scene needs an emitter: this one faces away
  const Linked linked(a);
  const Hierarchy& h = linked.h;
  const ClusterTree& tree = linked.tree;
  const InitialLinks links = linked.link(2.0);
  const std::int32_t inner_bottom = h.root(16, 1), inner_top = h.root(17, 0);
  const auto from_grid = [&](std::int32_t node) {
    const ClusterNode& n = tree.node(node);
    for (std::uint32_t i = n.first; i < n.first + n.count; ++i)
      if (h.element(tree.sides()[i]).patch < 16) return true;
    return false;
  };
  int outer_bottom_links = 0;
  for (const ClusterLink& l : links.clusters) {
    if (!from_grid(l.emitter)) continue;
    const ClusterNode& x = tree.node(l.receiver);
    for (std::uint32_t i = x.first; i < x.first + x.count; ++i) {
      const std::int32_t receiver = tree.sides()[i];
      EXPECT_NE(receiver, inner_bottom);
      EXPECT_NE(receiver, inner_top);
      outer_bottom_links += receiver == h.root(16, 0);
    }
  }
  for (const Link& l : links.elements) {
    if (h.element(l.emitter).patch >= 16) continue;
    EXPECT_NE(l.receiver, inner_bottom);
    outer_bottom_links += l.receiver == h.root(16, 0);
  }
  EXPECT_GT(outer_bottom_links, 0) << "the outside of the bottom sees the lights";
}

// Two 8 x 8 grids of 0.2 squares 0.5 apart (pairs of clusters closer than
// twice their radii), one reflecting the light of the other.
Arrays near_grids(double emit) {
  Arrays a;
  grid(a, 0.0, 8, true, 0.5, 0.0);
  grid(a, 0.5, 8, false, 0.5, emit);
  if (emit == 0.0) a.square(dvec3(0.0, 0.0, -50.0), 0.1, false, 0.0, 1.0);  // faces away
  return a;
}

// The criterion of a solve whose clusters send `light`, at `threshold`.
ClusterCriterion by_light(const Linked& linked, const ClusterLighting& light, double threshold) {
  ClusterCriterion c = by_separation(std::numeric_limits<double>::infinity());
  c.threshold = threshold;
  c.adaptation = 1.0;
  c.total_area = linked.scene.total_area;
  c.lighting = &light;
  return c;
}

TEST(ClusterCriterion, LittleLightLinksCloseClustersMuchLightDoesNot) {
  const Linked linked(near_grids(0.0));
  const auto faint = estimated_cluster_light(linked.tree, linked.h, 1e-3);
  const auto bright = estimated_cluster_light(linked.tree, linked.h, 1e3);
  const InitialLinks pairs = linked.link(std::numeric_limits<double>::infinity());
  const InitialLinks few = linked.link(by_light(linked, faint, 1e-4));
  const InitialLinks all = linked.link(by_light(linked, bright, 1e-4));
  EXPECT_EQ(pairs.clusters.size(), 0u);
  EXPECT_GT(few.clusters.size(), 0u);
  EXPECT_LT(few.clusters.size() + few.elements.size(), pairs.elements.size() / 2);
  EXPECT_EQ(all.clusters.size(), 0u);
  EXPECT_EQ(all.elements.size(), pairs.elements.size());
  // However little light, clusters nearer than twice their radii are not linked.
  for (const ClusterLink& l : few.clusters) {
    const ClusterNode& x = linked.tree.node(l.receiver);
    const ClusterNode& y = linked.tree.node(l.emitter);
    EXPECT_GT(glm::length(x.centre - y.centre), 2.0 * (x.radius + y.radius));
  }
  EXPECT_EQ(covered(linked.tree, few), covered(linked.tree, pairs));
}

TEST(ClusterCriterion, LightFromEmittersLinksByItsLightAlone) {
  // The emitting grid far away: distance alone never links emitters; a
  // faint enough light does.
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  grid(a, 20.0, 4, false, 0.0, 2.0);
  const Linked linked(a);
  const auto light = estimated_cluster_light(linked.tree, linked.h, 0.0);
  EXPECT_EQ(linked.link(by_light(linked, light, 1e-12)).clusters.size(), 0u);
  EXPECT_GT(linked.link(by_light(linked, light, 1.0)).clusters.size(), 0u);
}

TEST(ClusterCriterion, SplittingTooCoarseLinksCoversTheSamePairs) {
  const Linked linked(near_grids(0.0));
  const auto faint = estimated_cluster_light(linked.tree, linked.h, 1e-3);
  const InitialLinks coarse = linked.link(by_light(linked, faint, 1e-3));
  ASSERT_GT(coarse.clusters.size(), 0u);
  // Ten thousand times the light: the nearest links are too coarse now; what replaces them
  // covers exactly their pairs.
  const auto brighter = estimated_cluster_light(linked.tree, linked.h, 10.0);
  const ClusterCriterion finer = by_light(linked, brighter, 1e-3);
  InitialLinks after;
  after.elements = coarse.elements;
  std::vector<ClusterLink> split;
  for (const ClusterLink& l : coarse.clusters) {
    if (cluster_link_too_coarse(linked.tree, linked.h, l, finer))
      split.push_back(l);
    else
      after.clusters.push_back(l);
  }
  ASSERT_GT(split.size(), 0u);
  ASSERT_LT(split.size(), coarse.clusters.size());
  const InitialLinks made =
      split_cluster_links(linked.tree, linked.h, *linked.occluders.rays, finer, split, {});
  after.clusters.insert(after.clusters.end(), made.clusters.begin(), made.clusters.end());
  after.elements.insert(after.elements.end(), made.elements.begin(), made.elements.end());
  EXPECT_EQ(covered(linked.tree, after), covered(linked.tree, coarse));
  for (const ClusterLink& l : made.clusters)
    EXPECT_FALSE(cluster_link_too_coarse(linked.tree, linked.h, l, finer));
}

}  // namespace
}  // namespace radiosity
