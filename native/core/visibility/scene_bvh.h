// Bounding volume hierarchy over the scene's triangles, for region queries such
// as shaft culling (Haines and Wallace 1994): which triangles may touch a convex
// region. Rays go through Embree instead (ray_scene.h); this tree answers the
// questions Embree's ray API cannot.
//
// Binned SAH build over triangle bounds, flat node array in depth-first order
// (left child right after its parent), leaves of at most 4 triangles.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/triangle.h"
#include "radiosity/vec.h"

namespace radiosity {

struct Aabb {
  dvec3 lo{1e300};
  dvec3 hi{-1e300};

  void grow(const dvec3& p) {
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  void grow(const Aabb& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
  bool empty() const { return lo.x > hi.x; }
  double half_area() const {
    if (empty()) return 0.0;
    const dvec3 d = hi - lo;
    return d.x * d.y + d.y * d.z + d.z * d.x;
  }
};

struct BvhNode {
  Aabb box;
  // Leaf: `count` > 0 triangles at order[first, first + count).
  // Inner: count == 0, left child is the next node, right child is `first`.
  std::uint32_t first = 0;
  std::uint32_t count = 0;
};

struct SceneBvh {
  std::vector<BvhNode> nodes;
  std::vector<std::uint32_t> order;  // triangle indices, grouped by leaf
};

// Our binned SAH builder (single thread).
SceneBvh build_scene_bvh(std::span<const Triangle> triangles);

// The same tree layout built by Embree's rtcBuildBVH (SAH, its own threads),
// boxes recomputed in double precision from the triangles. Compared with ours
// in bench/visibility_bench.cpp.
SceneBvh build_scene_bvh_embree(std::span<const Triangle> triangles);

// Visits every triangle whose leaf box is not rejected by `keep_box(const Aabb&)`,
// calling `visit(std::uint32_t triangle)`. Depth-first with an explicit stack.
template <class KeepBox, class Visit>
void traverse_scene_bvh(const SceneBvh& bvh, KeepBox&& keep_box, Visit&& visit) {
  if (bvh.nodes.empty()) return;
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t index = stack[--top];
    const BvhNode& node = bvh.nodes[index];
    if (!keep_box(node.box)) continue;
    if (node.count > 0) {
      for (std::uint32_t i = node.first; i < node.first + node.count; ++i) visit(bvh.order[i]);
    } else if (top + 2 <= 128) {
      stack[top++] = node.first;
      stack[top++] = index + 1;
    }
  }
}

}  // namespace radiosity
