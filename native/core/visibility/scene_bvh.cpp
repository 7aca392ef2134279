// Binned SAH build of the scene's BVH (see scene_bvh.h).
#include "core/visibility/scene_bvh.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <array>
#include <new>
#include <stdexcept>

#include "core/visibility/embree_device.h"

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

// Embree's builder hands out nodes through callbacks; these are its nodes, in
// its thread-local memory, flattened into our layout afterwards.
struct EmbreeNode {
  bool leaf = false;
};
struct EmbreeInner : EmbreeNode {
  EmbreeNode* child[2] = {nullptr, nullptr};
};
struct EmbreeLeaf : EmbreeNode {
  std::uint32_t count = 0;
  std::uint32_t* triangle = nullptr;  // `count` entries, stored right after the leaf
};

void* create_inner(RTCThreadLocalAllocator alloc, unsigned int, void*) {
  return new (rtcThreadLocalAlloc(alloc, sizeof(EmbreeInner), 16)) EmbreeInner();
}
void set_children(void* node, void** children, unsigned int count, void*) {
  auto* inner = static_cast<EmbreeInner*>(node);
  for (unsigned int i = 0; i < count && i < 2; ++i)
    inner->child[i] = static_cast<EmbreeNode*>(children[i]);
}
void set_bounds(void*, const RTCBounds**, unsigned int, void*) {}  // recomputed in double
void* create_leaf(RTCThreadLocalAllocator alloc, const RTCBuildPrimitive* prims, size_t count,
                  void*) {
  // Leaves hold at most maxLeafSize triangles, unless the depth limit forced more.
  void* memory = rtcThreadLocalAlloc(alloc, sizeof(EmbreeLeaf) + count * sizeof(std::uint32_t), 16);
  auto* leaf = new (memory) EmbreeLeaf();
  leaf->leaf = true;
  leaf->count = static_cast<std::uint32_t>(count);
  leaf->triangle =
      reinterpret_cast<std::uint32_t*>(static_cast<unsigned char*>(memory) + sizeof(EmbreeLeaf));
  for (std::uint32_t i = 0; i < leaf->count; ++i) leaf->triangle[i] = prims[i].primID;
  return leaf;
}

// Depth-first copy into `bvh` (left child right after its parent); returns the
// node's index. Boxes come from the triangles, in double precision.
std::uint32_t flatten(const EmbreeNode* node, std::span<const Aabb> boxes, SceneBvh& bvh) {
  const auto index = static_cast<std::uint32_t>(bvh.nodes.size());
  bvh.nodes.emplace_back();
  if (node->leaf) {
    const auto* leaf = static_cast<const EmbreeLeaf*>(node);
    Aabb box;
    bvh.nodes[index].first = static_cast<std::uint32_t>(bvh.order.size());
    bvh.nodes[index].count = leaf->count;
    for (std::uint32_t i = 0; i < leaf->count; ++i) {
      bvh.order.push_back(leaf->triangle[i]);
      box.grow(boxes[leaf->triangle[i]]);
    }
    bvh.nodes[index].box = box;
    return index;
  }
  const auto* inner = static_cast<const EmbreeInner*>(node);
  flatten(inner->child[0], boxes, bvh);
  const std::uint32_t right = flatten(inner->child[1], boxes, bvh);
  Aabb box = bvh.nodes[index + 1].box;
  box.grow(bvh.nodes[right].box);
  bvh.nodes[index].box = box;
  bvh.nodes[index].first = right;
  bvh.nodes[index].count = 0;
  return index;
}

}  // namespace

SceneBvh build_scene_bvh_embree(std::span<const Triangle> triangles) {
  SceneBvh bvh;
  if (triangles.empty()) return bvh;
  std::vector<Aabb> boxes(triangles.size());
  // Embree may use spare room in the primitive array for spatial splits; we ask
  // for none, so the capacity is the count.
  std::vector<RTCBuildPrimitive> prims(triangles.size());
  for (std::size_t i = 0; i < triangles.size(); ++i) {
    for (const dvec3& v : triangles[i].v) boxes[i].grow(v);
    RTCBuildPrimitive& p = prims[i];
    // Float bounds rounded outwards (Embree only uses them to decide splits).
    p.lower_x = std::nextafter(static_cast<float>(boxes[i].lo.x), -1e30f);
    p.lower_y = std::nextafter(static_cast<float>(boxes[i].lo.y), -1e30f);
    p.lower_z = std::nextafter(static_cast<float>(boxes[i].lo.z), -1e30f);
    p.upper_x = std::nextafter(static_cast<float>(boxes[i].hi.x), 1e30f);
    p.upper_y = std::nextafter(static_cast<float>(boxes[i].hi.y), 1e30f);
    p.upper_z = std::nextafter(static_cast<float>(boxes[i].hi.z), 1e30f);
    p.geomID = 0;
    p.primID = static_cast<unsigned>(i);
  }
  RTCBVH handle = rtcNewBVH(shared_embree_device());
  RTCBuildArguments args = rtcDefaultBuildArguments();
  args.buildQuality = RTC_BUILD_QUALITY_HIGH;
  args.maxBranchingFactor = 2;
  args.maxDepth = 48;
  args.minLeafSize = 1;
  args.maxLeafSize = kLeafSize;
  args.bvh = handle;
  args.primitives = prims.data();
  args.primitiveCount = prims.size();
  args.primitiveArrayCapacity = prims.size();
  args.createNode = create_inner;
  args.setNodeChildren = set_children;
  args.setNodeBounds = set_bounds;
  args.createLeaf = create_leaf;
  const auto* root = static_cast<const EmbreeNode*>(rtcBuildBVH(&args));
  if (!root) {
    rtcReleaseBVH(handle);
    throw std::runtime_error("Embree: rtcBuildBVH failed");
  }
  bvh.nodes.reserve(2 * triangles.size() / kLeafSize + 1);
  bvh.order.reserve(triangles.size());
  flatten(root, boxes, bvh);
  rtcReleaseBVH(handle);  // frees the nodes made in its allocator
  return bvh;
}

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
