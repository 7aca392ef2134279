// The cluster tree and the cluster links: structure, facing, and that a far
// cluster sends what its sides would through their own exact links.
#include "core/solve/cluster_links.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

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

// A scene with its hierarchy, cluster tree and occluders, linked at `separation`.
struct Linked {
  explicit Linked(const Arrays& a)
      : scene(a.scene()), h(scene), tree(h), occluders(make_scene_occluders(scene)) {}
  InitialLinks link(double separation) const {
    return link_clusters(tree, h, *occluders.rays, separation, 16, {});
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
  EXPECT_LT(far.clusters.size() + far.elements.size(), 2u * 16 * 16);
  for (const ClusterLink& l : far.clusters) {
    EXPECT_TRUE(tree.node(l.receiver).is_leaf());  // a cluster link ends on one side
    EXPECT_NEAR(glm::length(dvec3(l.direction[0], l.direction[1], l.direction[2])), 1.0, 1e-6);
  }
  // Infinitely demanding separation: only pairs of sides.
  const InitialLinks pairs = linked.link(std::numeric_limits<double>::infinity());
  EXPECT_EQ(pairs.clusters.size(), 0u);
  EXPECT_EQ(pairs.elements.size(), 2u * 16 * 16);  // each grid lights the other (both reflect)
}

TEST(ClusterLinks, FarLightMatchesThePointFormFactorsOfItsSides) {
  // A 4 x 4 grid of lit squares (radiance 2) 20 above a 4 x 4 grid of
  // receivers: what each receiver gathers through cluster links against the
  // sum of the exact point-to-polygon form factors of the squares at its
  // centre. (Emitters themselves always go through face links.)
  Arrays a;
  grid(a, 0.0, 4, true, 0.5, 0.0);
  grid(a, 20.0, 4, false, 0.5, 0.0);
  a.square(dvec3(0.0, 0.0, -50.0), 0.1, false, 0.0,
           1.0);  // a scene needs an emitter: this one faces away
  const Linked linked(a);
  const Hierarchy& h = linked.h;
  const ClusterTree& tree = linked.tree;
  const InitialLinks links = linked.link(2.0);
  ASSERT_GT(links.clusters.size(), 0u);
  // Pairs the walk left to face links are not part of the cluster light.
  const auto face_linked = [&](std::int32_t receiver, std::int32_t emitter) {
    for (const Link& l : links.elements)
      if (l.receiver == receiver && l.emitter == emitter) return true;
    return false;
  };
  std::vector<Rgb> radiance(h.elements().size(), Rgb(0.0));
  for (std::uint32_t q = 16; q < 32; ++q) radiance[static_cast<size_t>(h.root(q, 0))] = Rgb(2.0);
  std::vector<Rgb> gathered(h.elements().size(), Rgb(0.0));
  ClusterGather gather;
  gather(tree, links.clusters, h, radiance, gathered);
  for (std::int32_t r = 0; r < 16; ++r) {
    const Element& receiver = h.element(h.root(static_cast<std::uint32_t>(r), 0));
    double exact = 0.0;
    for (std::uint32_t q = 16; q < 32; ++q) {
      if (face_linked(h.root(static_cast<std::uint32_t>(r), 0), h.root(q, 0))) continue;
      dvec3 c[4];
      const int n = h.corners(h.element(h.root(q, 0)), c);
      exact += 2.0 * form_factor(h.centre(receiver), h.normal(receiver),
                                 std::span<const dvec3>(c, static_cast<size_t>(n)));
    }
    EXPECT_NEAR(gathered[static_cast<size_t>(h.root(static_cast<std::uint32_t>(r), 0))].x, exact,
                0.01 * exact);
  }
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
    const std::int32_t receiver = tree.sides()[tree.node(l.receiver).first];
    if (!from_grid(l.emitter)) continue;
    EXPECT_NE(receiver, inner_bottom);
    EXPECT_NE(receiver, inner_top);
    outer_bottom_links += receiver == h.root(16, 0);
  }
  for (const Link& l : links.elements) {
    if (h.element(l.emitter).patch >= 16) continue;
    EXPECT_NE(l.receiver, inner_bottom);
    outer_bottom_links += l.receiver == h.root(16, 0);
  }
  EXPECT_GT(outer_bottom_links, 0) << "the outside of the bottom sees the lights";
}

}  // namespace
}  // namespace radiosity
