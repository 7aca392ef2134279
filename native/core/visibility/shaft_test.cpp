// Shaft culling (Haines and Wallace): the BVH query finds exactly the triangles a
// brute-force scan finds, never misses a triangle that blocks a segment between
// the two elements, and its "clear" and "hidden" answers are right.
#include "core/visibility/shaft.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <vector>

#include "core/visibility/sampled_visibility.h"

namespace radiosity {
namespace {

using Polygon = std::vector<dvec3>;

dvec3 random_point(std::mt19937_64& rng, double lo, double hi) {
  std::uniform_real_distribution<double> uni(lo, hi);
  return {uni(rng), uni(rng), uni(rng)};
}

// A random element: a triangle or a planar quad (parallelogram).
Polygon random_element(std::mt19937_64& rng, const dvec3& c, double size) {
  const dvec3 a = random_point(rng, -size, size), b = random_point(rng, -size, size);
  if (rng() % 2) return {c, c + a, c + b};
  return {c, c + a, c + a + b, c + b};
}

// A random point of a convex polygon (not uniform; any point will do).
dvec3 random_point_in(std::mt19937_64& rng, const Polygon& p) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<double> w(p.size());
  double sum = 0.0;
  for (double& x : w) sum += (x = uni(rng) + 1e-3);
  dvec3 q(0.0);
  for (std::size_t i = 0; i < p.size(); ++i) q += (w[i] / sum) * p[i];
  return q;
}

OccluderScene random_scene(std::mt19937_64& rng, int count) {
  std::vector<Triangle> triangles;
  for (int i = 0; i < count; ++i) {
    const dvec3 c = random_point(rng, -5.0, 5.0);
    // Mostly small triangles, a few large ones that can hide a whole link.
    const double size = i % 50 == 0 ? 4.0 : 0.4;
    triangles.push_back(
        Triangle{{c + random_point(rng, -size, size), c + random_point(rng, -size, size),
                  c + random_point(rng, -size, size)}});
  }
  return make_occluder_scene(std::move(triangles));
}

TEST(ShaftCulling, BvhFindsWhatBruteForceFindsAndMissesNoBlocker) {
  std::mt19937_64 rng(41);
  const OccluderScene scene = random_scene(rng, 1000);
  int links = 0, segments = 0, blockers = 0, hidden = 0, clear = 0;
  for (int i = 0; i < 300; ++i) {
    const dvec3 c = random_point(rng, -4.0, 4.0);
    const Polygon receiver = random_element(rng, c, 0.5);
    const Polygon emitter = random_element(rng, c + random_point(rng, -3.0, 3.0), 0.5);
    const std::uint32_t rf = static_cast<std::uint32_t>(rng() % 1000);
    const std::uint32_t ef = static_cast<std::uint32_t>(rng() % 1000);
    const ShaftCulling fast = cull_shaft(scene, receiver, rf, emitter, ef);
    const ShaftCulling slow = cull_shaft_brute_force(scene, receiver, rf, emitter, ef);
    ASSERT_EQ(fast.candidates, slow.candidates) << "link " << i;
    EXPECT_EQ(fast.visibility, slow.visibility);
    ++links;
    hidden += fast.visibility == ShaftVisibility::hidden;
    clear += fast.visibility == ShaftVisibility::clear;
    // Every triangle that blocks some segment between the elements is a candidate.
    for (int k = 0; k < 100; ++k) {
      const dvec3 a = random_point_in(rng, receiver), b = random_point_in(rng, emitter);
      ++segments;
      bool blocked = false;
      for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
        if (t == rf || t == ef || !segment_hits_triangle(a, b, scene.triangles[t])) continue;
        blocked = true;
        ++blockers;
        EXPECT_TRUE(std::binary_search(fast.candidates.begin(), fast.candidates.end(), t))
            << "link " << i << " misses blocker " << t;
      }
      if (fast.visibility == ShaftVisibility::clear) {
        EXPECT_FALSE(blocked);
      } else if (fast.visibility == ShaftVisibility::hidden) {
        EXPECT_TRUE(blocked);
      }
    }
  }
  std::printf("shaft culling: %d links, %d segments, %d blocker hits, %d clear, %d hidden\n", links,
              segments, blockers, clear, hidden);
  EXPECT_GT(blockers, 100);  // the scene does get in the way
  EXPECT_GT(clear, 10);
}

TEST(ShaftCulling, EmbreeBuiltBvhFindsTheSameCandidates) {
  std::mt19937_64 rng(43);
  OccluderScene scene = random_scene(rng, 3000);
  OccluderScene embree = scene;
  embree.bvh = build_scene_bvh_embree(embree.triangles);
  // Every triangle sits in exactly one leaf.
  std::vector<std::uint32_t> order = embree.bvh.order;
  std::sort(order.begin(), order.end());
  ASSERT_EQ(order.size(), scene.triangles.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) ASSERT_EQ(order[i], i);
  for (int i = 0; i < 200; ++i) {
    const dvec3 c = random_point(rng, -4.0, 4.0);
    const Polygon receiver = random_element(rng, c, 0.5);
    const Polygon emitter = random_element(rng, c + random_point(rng, -3.0, 3.0), 0.5);
    const ShaftCulling ours = cull_shaft(scene, receiver, kNoFace, emitter, kNoFace);
    const ShaftCulling theirs = cull_shaft(embree, receiver, kNoFace, emitter, kNoFace);
    const ShaftCulling brute = cull_shaft_brute_force(scene, receiver, kNoFace, emitter, kNoFace);
    ASSERT_EQ(ours.candidates, brute.candidates);
    ASSERT_EQ(theirs.candidates, brute.candidates);
  }
}

TEST(ShaftCulling, WallBetweenTwoElementsIsHidden) {
  // Floor element, ceiling element, and a wall quad (one face, two triangles)
  // between them; then a wall with a hole-like gap (two faces side by side).
  std::vector<Triangle> triangles{
      Triangle{{dvec3(-3, -3, 1), dvec3(3, -3, 1), dvec3(3, 3, 1)}},
      Triangle{{dvec3(-3, -3, 1), dvec3(3, 3, 1), dvec3(-3, 3, 1)}},
  };
  const Polygon floor{{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  const Polygon ceiling{{0, 0, 2}, {0, 1, 2}, {1, 1, 2}, {1, 0, 2}};
  OccluderScene scene = make_occluder_scene(triangles, {0, 0});
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility,
            ShaftVisibility::hidden);
  // As two faces: neither alone covers the shaft's cross-section, together they do.
  scene = make_occluder_scene(triangles, {0, 1});
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility,
            ShaftVisibility::hidden);
  // A wall of 8 x 8 quads (128 triangles, one face each): hidden.
  std::vector<Triangle> tiles;
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) {
      const dvec3 a(-3 + 0.75 * i, -3 + 0.75 * j, 1),
          b = a + dvec3(0.75, 0, 0), c = a + dvec3(0.75, 0.75, 0), d = a + dvec3(0, 0.75, 0);
      tiles.push_back(Triangle{{a, b, c}});
      tiles.push_back(Triangle{{a, c, d}});
    }
  scene = make_occluder_scene(tiles);
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility,
            ShaftVisibility::hidden);
  // The same wall with one tile missing inside the shaft: light gets through.
  std::vector<Triangle> holed;
  for (const Triangle& t : tiles)
    if (!(t.v[0].x == 0.0 && t.v[0].y == 0.0)) holed.push_back(t);
  ASSERT_EQ(holed.size(), tiles.size() - 2);
  scene = make_occluder_scene(holed);
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility,
            ShaftVisibility::partial);
  // Two halves with a crack of 1e-3 between them: partial.
  std::vector<Triangle> cracked{
      Triangle{{dvec3(-3, -3, 1), dvec3(0.5, -3, 1), dvec3(0.5, 3, 1)}},
      Triangle{{dvec3(-3, -3, 1), dvec3(0.5, 3, 1), dvec3(-3, 3, 1)}},
      Triangle{{dvec3(0.501, -3, 1), dvec3(3, -3, 1), dvec3(3, 3, 1)}},
      Triangle{{dvec3(0.501, -3, 1), dvec3(3, 3, 1), dvec3(0.501, 3, 1)}}};
  scene = make_occluder_scene(cracked);
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility,
            ShaftVisibility::partial);
  // The wall is the receiver's own face: ignored, so the link is clear.
  scene = make_occluder_scene(triangles, {0, 0});
  EXPECT_EQ(cull_shaft(scene, floor, 0, ceiling, kNoFace).visibility, ShaftVisibility::clear);
  // A wall beside the shaft: clear.
  std::vector<Triangle> beside{Triangle{{dvec3(2, -3, 0.5), dvec3(2, 3, 0.5), dvec3(2, 0, 1.5)}}};
  scene = make_occluder_scene(beside);
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility, ShaftVisibility::clear);
  // A neighbour touching the floor element along an edge, in the floor's plane: clear.
  std::vector<Triangle> neighbour{Triangle{{dvec3(1, 0, 0), dvec3(2, 0, 0), dvec3(1, 1, 0)}}};
  scene = make_occluder_scene(neighbour);
  EXPECT_EQ(cull_shaft(scene, floor, kNoFace, ceiling, kNoFace).visibility, ShaftVisibility::clear);
}

}  // namespace
}  // namespace radiosity
