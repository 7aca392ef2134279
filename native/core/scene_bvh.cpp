// Binned SAH build of the scene's BVH (see scene_bvh.h).
#include "core/scene_bvh.h"

#include <algorithm>
#include <array>

namespace radiosity {
namespace {

constexpr int kBins = 16;
constexpr std::uint32_t kLeafSize = 4;

struct BuildItem {
  Aabb box;
  dvec3 centre{0.0};
};

struct Builder {
  std::vector<BuildItem> items;
  std::vector<std::uint32_t>& order;
  std::vector<BvhNode>& nodes;

  // Builds the subtree over order[first, first + count) into nodes[index].
  void build(std::uint32_t index, std::uint32_t first, std::uint32_t count, int depth) {
    Aabb box, centres;
    for (std::uint32_t i = first; i < first + count; ++i) {
      box.grow(items[order[i]].box);
      centres.grow(items[order[i]].centre);
    }
    nodes[index].box = box;
    // Stack depth of the traversal bounds the tree depth; degenerate input (all
    // centres equal) cannot be split and becomes a larger leaf.
    if (count <= kLeafSize || depth >= 60) return make_leaf(index, first, count);
    const dvec3 extent = centres.hi - centres.lo;
    int axis = 0;
    if (extent.y > extent[axis]) axis = 1;
    if (extent.z > extent[axis]) axis = 2;
    if (!(extent[axis] > 0.0)) return make_leaf(index, first, count);

    // Surface area heuristic over kBins bins of centroid position along the axis.
    std::array<Aabb, kBins> bin_box;
    std::array<std::uint32_t, kBins> bin_count{};
    const double scale = kBins / extent[axis];
    const auto bin_of = [&](std::uint32_t t) {
      const int b = static_cast<int>((items[t].centre[axis] - centres.lo[axis]) * scale);
      return std::clamp(b, 0, kBins - 1);
    };
    for (std::uint32_t i = first; i < first + count; ++i) {
      const int b = bin_of(order[i]);
      bin_box[b].grow(items[order[i]].box);
      ++bin_count[b];
    }
    std::array<double, kBins> right_cost{};
    Aabb acc;
    std::uint32_t n = 0;
    for (int b = kBins - 1; b > 0; --b) {
      acc.grow(bin_box[b]);
      n += bin_count[b];
      right_cost[b] = acc.half_area() * n;
    }
    double best = 1e300;
    int split = -1;
    acc = Aabb{};
    n = 0;
    for (int b = 0; b < kBins - 1; ++b) {
      acc.grow(bin_box[b]);
      n += bin_count[b];
      const double cost = acc.half_area() * n + right_cost[b + 1];
      if (n > 0 && n < count && cost < best) best = cost, split = b;
    }
    if (split < 0) return make_leaf(index, first, count);
    const auto mid_it = std::partition(order.begin() + first, order.begin() + first + count,
                                       [&](std::uint32_t t) { return bin_of(t) <= split; });
    const auto left_count = static_cast<std::uint32_t>(mid_it - (order.begin() + first));
    if (left_count == 0 || left_count == count) return make_leaf(index, first, count);

    nodes.emplace_back();  // left child at index + 1 (depth-first order)
    const auto left = static_cast<std::uint32_t>(nodes.size() - 1);
    build(left, first, left_count, depth + 1);
    nodes.emplace_back();
    const auto right = static_cast<std::uint32_t>(nodes.size() - 1);
    nodes[index].first = right;
    nodes[index].count = 0;
    build(right, first + left_count, count - left_count, depth + 1);
  }

  void make_leaf(std::uint32_t index, std::uint32_t first, std::uint32_t count) {
    nodes[index].first = first;
    nodes[index].count = count;
  }
};

}  // namespace

SceneBvh build_scene_bvh(std::span<const Triangle> triangles) {
  SceneBvh bvh;
  if (triangles.empty()) return bvh;
  bvh.order.resize(triangles.size());
  for (std::uint32_t i = 0; i < bvh.order.size(); ++i) bvh.order[i] = i;
  Builder builder{{}, bvh.order, bvh.nodes};
  builder.items.resize(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (const dvec3& v : triangles[i].v) builder.items[i].box.grow(v);
    builder.items[i].centre = 0.5 * (builder.items[i].box.lo + builder.items[i].box.hi);
  }
  bvh.nodes.reserve(2 * triangles.size() / kLeafSize + 1);
  bvh.nodes.emplace_back();
  builder.build(0, 0, static_cast<std::uint32_t>(triangles.size()), 0);
  return bvh;
}

}  // namespace radiosity
