#include "core/solve/cluster_links.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <numbers>
#include <span>

#include "core/geometry/random.h"

namespace radiosity {
namespace {

// Does every side of `node` face direction `w` (normals within 90 degrees),
// for every direction within `cone` of w? And does none?
bool all_facing(const ClusterNode& node, const dvec3& w, double cone) {
  const double angle = std::acos(std::clamp(glm::dot(node.axis, w), -1.0, 1.0));
  return angle + node.spread + cone < 0.5 * std::numbers::pi - 1e-6;
}
bool none_facing(const ClusterNode& node, const dvec3& w, double cone) {
  const double angle = std::acos(std::clamp(glm::dot(node.axis, w), -1.0, 1.0));
  return angle - node.spread - cone > 0.5 * std::numbers::pi + 1e-6;
}

// Two flat nodes (every side facing along its axis) that cannot exchange
// light: facing the same way (each side sees only what rises above its own
// plane, and the other must see it back), or facing opposite ways with no
// side of the emitter above a side of the receiver (the two halves of a
// two-sided floor). The walk would reach the same verdict at every pair of
// leaves (n^2 pairs over a tiled floor), but for grazing cluster links between
// coplanar sides, which carry no light (3 of 286 in a 300-face box field; the
// radiance moved by 2e-7).
bool flat_pair_apart(const ClusterNode& rx, const ClusterNode& ry) {
  if (!rx.is_flat() || !ry.is_flat()) return false;
  const double c = glm::dot(rx.axis, ry.axis);
  const double parallel = std::cos(2.0 * ClusterNode::kFlatSpread);
  if (c > parallel) return true;
  if (c >= -parallel) return false;
  // Heights along rx's axis: the emitter's highest is -ry.height_lo.
  const double tolerance = 1e-9 * (rx.radius + ry.radius);
  return -ry.height_lo <= rx.height_lo + tolerance;
}

// Each side of the tree (in the tree's order) as the walk's rays sample it:
// its face and its corners, a quad as two triangles with the first one's share
// of the area. Made once per walk rather than read through the hierarchy for
// each of the 32 points of every cluster link's rays.
struct SideSample {
  dvec3 c[4];
  double first = 0.0, total = 0.0;  // the first triangle's area and both (times 2)
  std::uint32_t face = 0;
  bool quad = false;
};

std::vector<SideSample> side_samples(const ClusterTree& tree, const Hierarchy& hierarchy) {
  std::vector<SideSample> out(tree.sides().size());
  for (size_t i = 0; i < out.size(); ++i) {
    const Element& e = hierarchy.element(tree.sides()[i]);
    SideSample& s = out[i];
    s.face = hierarchy.patch_of(e).surface;
    s.quad = hierarchy.corners(e, s.c) == 4;
    if (s.quad) {
      s.first = glm::length(glm::cross(s.c[1] - s.c[0], s.c[2] - s.c[0]));
      s.total = s.first + glm::length(glm::cross(s.c[2] - s.c[0], s.c[3] - s.c[0]));
    }
  }
  return out;
}

// A point uniformly distributed over the node's sides (area-weighted).
dvec3 random_point(const ClusterTree& tree, std::span<const SideSample> sides,
                   const ClusterNode& node, SplitMix64& random, std::uint32_t& face) {
  const auto& prefix = tree.area_prefix();
  const double target = prefix[node.first] +
                        random.uniform() * (prefix[node.first + node.count] - prefix[node.first]);
  const auto it = std::upper_bound(prefix.begin() + node.first + 1,
                                   prefix.begin() + node.first + node.count, target);
  const SideSample& side = sides[static_cast<size_t>(it - prefix.begin()) - 1];
  face = side.face;
  dvec3 a = side.c[0], b = side.c[1], t = side.c[2];
  if (side.quad && random.uniform() * side.total >= side.first) b = side.c[2], t = side.c[3];
  const double s = std::sqrt(random.uniform()), r = random.uniform();
  return (1 - s) * a + s * (1 - r) * b + s * r * t;
}

// What the walk does with one pair of clusters.
struct PairOutcome {
  enum Kind : std::uint8_t {
    Drop,
    ClusterPair,
    ElementPair,
    SplitReceiver,
    SplitEmitter,
    SplitBoth
  } kind = Drop;
  ClusterLink link;  // ClusterPair: the link; ElementPair: its receiver and emitter elements
};

// Of `rays` shadow rays between random points of the two clusters' sides, how
// many pass. Seeded by the pair: the answer does not depend on threads.
int passing_rays(const ClusterTree& tree, std::span<const SideSample> sides, const RayScene& scene,
                 std::int32_t receiver, std::int32_t emitter, int rays) {
  SplitMix64 random{(static_cast<std::uint64_t>(static_cast<std::uint32_t>(receiver)) << 32) |
                    static_cast<std::uint32_t>(emitter)};
  int passed = 0;
  for (int k = 0; k < rays; ++k) {
    std::uint32_t from_face = 0, to_face = 0;
    const dvec3 from = random_point(tree, sides, tree.node(emitter), random, from_face);
    const dvec3 to = random_point(tree, sides, tree.node(receiver), random, to_face);
    passed += scene.occluded(from, to, from_face, to_face) ? 0 : 1;
  }
  return passed;
}

PairOutcome classify(const ClusterTree& tree, const Hierarchy& hierarchy,
                     std::span<const SideSample> sides, const RayScene& scene, double separation,
                     int rays, std::int32_t x, std::int32_t y) {
  PairOutcome out;
  const ClusterNode& rx = tree.node(x);
  const ClusterNode& ry = tree.node(y);
  if (!rx.reflects || !ry.sends) return out;
  const auto split = [&](PairOutcome::Kind kind) {
    out.kind = kind;
    return out;
  };
  if (x == y) return rx.is_leaf() ? out : split(PairOutcome::SplitBoth);
  if (flat_pair_apart(rx, ry)) return out;
  const bool both_leaves = rx.is_leaf() && ry.is_leaf();
  const dvec3 between = rx.centre - ry.centre;
  const double d = glm::length(between);
  if (d > 0.0) {
    const dvec3 w = between / d;
    // Directions between any two points of the two bounds.
    const double cone =
        d > rx.radius + ry.radius ? std::asin((rx.radius + ry.radius) / d) : 0.5 * std::numbers::pi;
    if (none_facing(ry, w, cone) || none_facing(rx, -w, cone)) return out;
    // Facing is judged along the centres' direction only: where the clusters
    // are far apart, a side seen at a grazing angle from part of the other
    // carries little light either way.
    // Light straight from emitters, the brightest in any scene, always goes
    // through face links (exact visibility at the receiver's samples).
    if (!both_leaves && !ry.emits && d > separation * (rx.radius + ry.radius) &&
        all_facing(ry, w, 0.0) && all_facing(rx, -w, 0.0)) {
      // A cluster link ends on one side: the distance to the emitter cluster
      // is then that side's own (a receiving cluster would give the light of
      // its centre to every side, off by 2 r / d).
      if (!rx.is_leaf()) return split(PairOutcome::SplitReceiver);
      const int passed = passing_rays(tree, sides, scene, x, y, rays);
      if (passed == 0) return out;
      out.kind = PairOutcome::ClusterPair;
      out.link.receiver = x;
      out.link.emitter = y;
      out.link.direction = {static_cast<float>(w.x), static_cast<float>(w.y),
                            static_cast<float>(w.z)};
      out.link.coupling = static_cast<float>(passed) / static_cast<float>(rays) /
                          static_cast<float>(std::numbers::pi * d * d);
      return out;
    }
  }
  if (both_leaves) {
    const std::int32_t p = tree.sides()[rx.first], q = tree.sides()[ry.first];
    const Element& receiver = hierarchy.element(p);
    const Element& emitter = hierarchy.element(q);
    if (receiver.patch == emitter.patch || !elements_face_each_other(hierarchy, receiver, emitter))
      return out;
    out.kind = PairOutcome::ElementPair;
    out.link.receiver = p;
    out.link.emitter = q;
    return out;
  }
  // Split the larger cluster.
  return split(!rx.is_leaf() && (ry.is_leaf() || rx.radius >= ry.radius)
                   ? PairOutcome::SplitReceiver
                   : PairOutcome::SplitEmitter);
}

}  // namespace

namespace {

void append(InitialLinks& to, const PairOutcome& o) {
  if (o.kind == PairOutcome::ClusterPair) {
    to.clusters.push_back(o.link);
  } else if (o.kind == PairOutcome::ElementPair) {
    Link link;
    link.receiver = o.link.receiver;
    link.emitter = o.link.emitter;
    to.elements.push_back(link);
  }
}

// The pairs a split makes, in a fixed order.
int children(const ClusterTree& tree, const PairOutcome& o, std::int32_t x, std::int32_t y,
             std::pair<std::int32_t, std::int32_t>* out) {
  int n = 0;
  switch (o.kind) {
    case PairOutcome::SplitReceiver:
      for (std::int32_t c : tree.node(x).child) out[n++] = {c, y};
      break;
    case PairOutcome::SplitEmitter:
      for (std::int32_t c : tree.node(y).child) out[n++] = {x, c};
      break;
    case PairOutcome::SplitBoth:
      for (std::int32_t a : tree.node(x).child)
        for (std::int32_t b : tree.node(x).child) out[n++] = {a, b};
      break;
    default:
      break;
  }
  return n;
}

}  // namespace

InitialLinks link_clusters(const ClusterTree& tree, const Hierarchy& hierarchy,
                           const RayScene& scene, double separation, int rays,
                           const std::function<bool()>& cancelled,
                           const std::function<void(double)>& progress) {
  InitialLinks links;
  if (tree.root() == kNone) return links;
  using Pair = std::pair<std::int32_t, std::int32_t>;
  const std::vector<SideSample> sides = side_samples(tree, hierarchy);
  const auto classify_pair = [&](const Pair& p) {
    return classify(tree, hierarchy, sides, scene, separation, rays, p.first, p.second);
  };
  // Breadth first until there are enough pairs to share between threads, then
  // each pair's subtree depth first (memory stays that of one path per
  // thread), each into its own lists, joined in pair order: the links do not
  // depend on the thread count.
  // Cancellation (and the time budget) is checked every kCheckEvery pairs a
  // thread classifies: one pair's subtree can hold millions of pairs.
  constexpr int kCheckEvery = 4096;
  std::atomic<bool> stop{false};
  const auto should_stop = [&] {
    if (!stop.load(std::memory_order_relaxed) && cancelled && cancelled()) stop = true;
    return stop.load(std::memory_order_relaxed);
  };
  std::vector<Pair> frontier{{tree.root(), tree.root()}};
  while (!frontier.empty() && frontier.size() < 4096 && !should_stop()) {
    std::vector<Pair> next;
    for (const Pair& p : frontier) {
      const PairOutcome o = classify_pair(p);
      append(links, o);
      Pair made[4];
      const int n = children(tree, o, p.first, p.second, made);
      next.insert(next.end(), made, made + n);
    }
    frontier = std::move(next);
  }
  std::vector<InitialLinks> found(frontier.size());
  const size_t chunk = 256;  // pairs between cancellation checks
  for (size_t begin = 0; begin < frontier.size() && !should_stop(); begin += chunk) {
    const size_t end = std::min(frontier.size(), begin + chunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end, 1), [&](const auto& range) {
      std::vector<Pair> stack;
      int since_check = 0;
      for (size_t i = range.begin(); i != range.end(); ++i) {
        stack.assign(1, frontier[i]);
        while (!stack.empty()) {
          if (++since_check == kCheckEvery) {
            since_check = 0;
            if (should_stop()) return;
          }
          const Pair p = stack.back();
          stack.pop_back();
          const PairOutcome o = classify_pair(p);
          append(found[i], o);
          Pair made[4];
          const int n = children(tree, o, p.first, p.second, made);
          for (int k = n; k-- > 0;) stack.push_back(made[k]);  // first child on top: visited first
        }
      }
    });
    if (progress) progress(static_cast<double>(end) / static_cast<double>(frontier.size()));
  }
  for (InitialLinks& part : found) {
    links.clusters.insert(links.clusters.end(), part.clusters.begin(), part.clusters.end());
    links.elements.insert(links.elements.end(), part.elements.begin(), part.elements.end());
    part = {};
  }
  return links;
}

void ClusterGather::operator()(const ClusterTree& tree, const std::vector<ClusterLink>& links,
                               const Hierarchy& hierarchy, const std::vector<Rgb>& radiance,
                               std::vector<Rgb>& gathered) {
  const auto& nodes = tree.nodes();
  power_.assign(nodes.size(), ChannelVectors{});
  // Power vectors, leaves up (children come after their parent).
  for (size_t i = nodes.size(); i-- > 0;) {
    const ClusterNode& node = nodes[i];
    ChannelVectors& p = power_[i];
    if (node.is_leaf()) {
      const std::int32_t side = tree.sides()[node.first];
      const Element& e = hierarchy.element(side);
      const Rgb& l = radiance[static_cast<size_t>(side)];
      const dvec3 n = e.area * hierarchy.normal(e);
      p = {l.x * n, l.y * n, l.z * n};
    } else {
      for (int c = 0; c < 3; ++c)
        p[static_cast<size_t>(c)] =
            power_[static_cast<size_t>(node.child[0])][static_cast<size_t>(c)] +
            power_[static_cast<size_t>(node.child[1])][static_cast<size_t>(c)];
    }
  }
  // Each link: the emitter's intensity towards the receiving side, taken
  // through that side's own normal.
  gathered.assign(gathered.size(), Rgb(0.0));
  for (const ClusterLink& link : links) {
    const dvec3 w(link.direction[0], link.direction[1], link.direction[2]);
    const ChannelVectors& p = power_[static_cast<size_t>(link.emitter)];
    const std::int32_t side = tree.sides()[tree.node(link.receiver).first];
    const double cosine = std::max(0.0, -glm::dot(hierarchy.normal(hierarchy.element(side)), w));
    Rgb& g = gathered[static_cast<size_t>(side)];
    for (int c = 0; c < 3; ++c)
      g[c] += static_cast<double>(link.coupling) * cosine *
              std::max(0.0, glm::dot(p[static_cast<size_t>(c)], w));
  }
}

}  // namespace radiosity
