#include "core/solve/cluster_links.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <limits>
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

// The area the node's sides show towards w: the sum of A max(0, n . w),
// from the area-normal sum wherever a node faces w whole (or not at all).
double facing_area(const ClusterTree& tree, std::int32_t index, const dvec3& w) {
  const ClusterNode& node = tree.node(index);
  if (all_facing(node, w, 0.0)) return glm::dot(node.area_normal, w);
  if (none_facing(node, w, 0.0)) return 0.0;
  if (node.is_leaf()) return std::max(0.0, glm::dot(node.area_normal, w));
  return facing_area(tree, node.child[0], w) + facing_area(tree, node.child[1], w);
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

// A point of the node's sides, weighted by `prefix` (area, or flux: sums over
// the sides in tree order): the side holding the quantile `u` of the node,
// then a uniform point of it. Area where the node holds no flux.
dvec3 point_at(std::span<const double> prefix, std::span<const SideSample> sides,
               const ClusterNode& node, double u, SplitMix64& random, std::uint32_t& face) {
  const double target =
      prefix[node.first] + u * (prefix[node.first + node.count] - prefix[node.first]);
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
// many pass. The points are stratified over each cluster (ray k ends in the
// k-th of `rays` equal shares of the receiver's area, and starts in the
// share counted from the other end of the emitter's flux: the visible
// fraction is of the light it sends), so a side holding a share gets a ray:
// a small side hidden behind the rest of its cluster is not missed by
// chance. Seeded by the pair: the answer does not depend on threads.
int passing_rays(const ClusterTree& tree, std::span<const SideSample> sides, const RayScene& scene,
                 std::span<const double> flux_prefix, std::int32_t receiver, std::int32_t emitter,
                 int rays) {
  const ClusterNode& from_node = tree.node(emitter);
  const bool by_flux = !flux_prefix.empty() && flux_prefix[from_node.first + from_node.count] >
                                                   flux_prefix[from_node.first];
  const std::span<const double> from_prefix = by_flux ? flux_prefix : tree.area_prefix();
  SplitMix64 random{(static_cast<std::uint64_t>(static_cast<std::uint32_t>(receiver)) << 32) |
                    static_cast<std::uint32_t>(emitter)};
  int passed = 0;
  for (int k = 0; k < rays; ++k) {
    std::uint32_t from_face = 0, to_face = 0;
    const double share_from = (rays - 1 - k + random.uniform()) / rays;
    const double share_to = (k + random.uniform()) / rays;
    const dvec3 from = point_at(from_prefix, sides, from_node, share_from, random, from_face);
    const dvec3 to =
        point_at(tree.area_prefix(), sides, tree.node(receiver), share_to, random, to_face);
    passed += scene.occluded(from, to, from_face, to_face) ? 0 : 1;
  }
  return passed;
}

// Nearer than this many times the sum of their radii, no pair is one link:
// the point approximation has no bound there (the gap could be nothing).
constexpr double kMinSeparation = 2.0;

// The light a link from cluster y to cluster x (centres d apart) could
// carry, over the adaptation radiance times the total area (infinite where
// the criterion knows no light), and whether distance alone takes the pair.
// Light straight from emitters, the brightest in any scene, is taken only by
// the light it carries, never by distance alone.
struct Judgement {
  bool too_near = true;      // nearer than kMinSeparation: never one link
  bool by_distance = false;  // further than the separation
  double light = 0.0;        // relative, as above
  double error = 1.0;        // relative error of the point approximation
};

Judgement judge(const ClusterNode& rx, const ClusterNode& ry, std::int32_t y, double d,
                const ClusterCriterion& c) {
  Judgement j;
  const double sum = rx.radius + ry.radius;
  j.too_near = !(d > kMinSeparation * sum);
  j.by_distance = !ry.emits && d > c.separation * sum;
  j.error = std::min(1.0, 2.0 * sum / d);
  if (!c.lighting || !(c.adaptation > 0.0)) {
    j.light = std::numeric_limits<double>::infinity();
    return j;
  }
  const ClusterLight& light = c.lighting->nodes[static_cast<size_t>(y)];
  const double gap = d - sum;
  const double irradiance =
      gap > 0.0 ? std::min(static_cast<double>(light.peak),
                           static_cast<double>(light.flux) / (std::numbers::pi * gap * gap))
                : static_cast<double>(light.peak);
  j.light =
      static_cast<double>(rx.reflectance) * rx.area * irradiance / (c.adaptation * c.total_area);
  return j;
}

// Whether the pair may be one link before its visibility is known.
bool faint(double light, const ClusterCriterion& c) {
  return std::isfinite(c.threshold) && light <= c.threshold;
}
bool may_link(const Judgement& j, const ClusterCriterion& c) {
  return !j.too_near && (j.by_distance || faint(j.light * j.error, c));
}

// What the shadow rays make of a pair that may be one link. Where they are
// partly blocked, the visible fraction stands for every part of both
// clusters: a side behind an occluder gets the average. That is taken for a
// link whose whole light, weighed kShadowWeight times (a shadow in the wrong
// place is what shows first: the insides of a field of boxes lit through
// their walls), is below the threshold, or (far enough apart) one ending on a
// single side, which then sees the emitter cluster's average; otherwise the
// pair is split, down to pairs of sides, whose links see exactly. None passing says the pair is
// hidden, which is taken where a mistake would cost little (a reflecting cluster far apart) and
// otherwise checked the same way: a lamp must not go dark by sixteen unlucky rays.
constexpr double kShadowWeight = 10.0;
enum class RayVerdict : std::uint8_t { Link, Hidden, Split };
RayVerdict ray_verdict(const Judgement& j, const ClusterCriterion& c, float visibility,
                       bool single_receiver) {
  if (visibility >= 1.0f) return RayVerdict::Link;
  const bool shadow_faint = faint(kShadowWeight * j.light, c);
  if (visibility <= 0.0f)
    return j.by_distance || shadow_faint ? RayVerdict::Hidden : RayVerdict::Split;
  return shadow_faint || (j.by_distance && single_receiver) ? RayVerdict::Link : RayVerdict::Split;
}

struct Walk {
  const ClusterTree& tree;
  const Hierarchy& hierarchy;
  std::span<const SideSample> sides;
  const RayScene& scene;
  const ClusterCriterion& criterion;

  PairOutcome classify(std::int32_t x, std::int32_t y) const;
};

PairOutcome Walk::classify(std::int32_t x, std::int32_t y) const {
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
    const Judgement judgement = judge(rx, ry, y, d, criterion);
    const bool emitter_faces = all_facing(ry, w, 0.0);
    const bool receiver_faces = all_facing(rx, -w, 0.0);
    if (may_link(judgement, criterion) &&
        ((emitter_faces && receiver_faces) || faint(judgement.light, criterion))) {
      const int passed =
          passing_rays(tree, sides, scene,
                       criterion.lighting ? std::span<const double>(criterion.lighting->flux_prefix)
                                          : std::span<const double>(),
                       x, y, criterion.rays);
      const float visibility = static_cast<float>(passed) / static_cast<float>(criterion.rays);
      const RayVerdict verdict = ray_verdict(judgement, criterion, visibility, rx.is_leaf());
      if (verdict == RayVerdict::Hidden) return out;
      if (verdict == RayVerdict::Link) {
        out.kind = PairOutcome::ClusterPair;
        out.link.receiver = x;
        out.link.emitter = y;
        out.link.visibility = visibility;
        if (emitter_faces && receiver_faces)
          out.link.extent = static_cast<float>(extent_correction(rx, ry));
        if (!emitter_faces) {
          out.link.isotropic = 1;
          out.link.shown = static_cast<float>(facing_area(tree, y, w) / ry.area);
        }
        if (!receiver_faces) {
          out.link.spherical = 1;
          out.link.seen = static_cast<float>(facing_area(tree, x, -w) / rx.area);
        }
        return out;
      }
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

using Pair = std::pair<std::int32_t, std::int32_t>;

// The walk from `start`: breadth first until there are enough pairs to share
// between threads (when `widen`), then each pair's subtree depth first
// (memory stays that of one path per thread), each into its own lists, joined
// in pair order: the links do not depend on the thread count. Cancellation
// (and the time budget) is checked every kCheckEvery pairs a thread
// classifies: one pair's subtree can hold millions of pairs.
InitialLinks walk_from(const Walk& walk, std::vector<Pair> frontier, bool widen,
                       const std::function<bool()>& cancelled,
                       const std::function<void(double)>& progress) {
  constexpr int kCheckEvery = 4096;
  constexpr size_t kWide = 4096;
  InitialLinks links;
  std::atomic<bool> stop{false};
  const auto should_stop = [&] {
    if (!stop.load(std::memory_order_relaxed) && cancelled && cancelled()) stop = true;
    return stop.load(std::memory_order_relaxed);
  };
  while (widen && !frontier.empty() && frontier.size() < kWide && !should_stop()) {
    std::vector<Pair> next;
    for (const Pair& p : frontier) {
      const PairOutcome o = walk.classify(p.first, p.second);
      append(links, o);
      Pair made[4];
      const int n = children(walk.tree, o, p.first, p.second, made);
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
          const PairOutcome o = walk.classify(p.first, p.second);
          append(found[i], o);
          Pair made[4];
          const int n = children(walk.tree, o, p.first, p.second, made);
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

// The real spherical harmonics of order 0 to 2 at the unit vector n.
std::array<double, 9> harmonics(const dvec3& n) {
  return {0.282095,
          0.488603 * n.y,
          0.488603 * n.z,
          0.488603 * n.x,
          1.092548 * n.x * n.y,
          1.092548 * n.y * n.z,
          0.315392 * (3.0 * n.z * n.z - 1.0),
          1.092548 * n.x * n.z,
          0.546274 * (n.x * n.x - n.y * n.y)};
}

// The clamped cosine's coefficients per band (pi, 2 pi / 3, pi / 4), per harmonic.
constexpr double kBand0 = std::numbers::pi, kBand1 = 2.0 * std::numbers::pi / 3.0,
                 kBand2 = std::numbers::pi / 4.0;
constexpr std::array<double, 9> kClampedCosine = {kBand0, kBand1, kBand1, kBand1, kBand2,
                                                  kBand2, kBand2, kBand2, kBand2};

// An axis-aligned box (empty: lo above hi).
struct Box {
  dvec3 lo{std::numeric_limits<double>::infinity()};
  dvec3 hi{-std::numeric_limits<double>::infinity()};
  void add(const Box& b) {
    lo = glm::min(lo, b.lo);
    hi = glm::max(hi, b.hi);
  }
};

// Per cluster node, a box holding every emitter cluster that sends to it or
// to one of its ancestors through `links`: what a side of it could receive
// from lies there.
std::vector<Box> senders(const ClusterTree& tree, std::span<const ClusterLink> links) {
  const auto& nodes = tree.nodes();
  std::vector<Box> box(nodes.size());
  for (const ClusterLink& l : links) {
    const ClusterNode& y = tree.node(l.emitter);
    box[static_cast<size_t>(l.receiver)].add(
        {y.centre - dvec3(y.radius), y.centre + dvec3(y.radius)});
  }
  for (size_t i = 0; i < nodes.size(); ++i)  // parents before children
    if (!nodes[i].is_leaf())
      for (std::int32_t c : nodes[i].child) box[static_cast<size_t>(c)].add(box[i]);
  return box;
}

// Does any of the box lie in front of the side's plane? A side in a
// receiving cluster with every sender behind it (the outside of a ceiling
// clustered with the inside of the floor) receives nothing, however the
// cluster's light extrapolates to it.
bool faces_senders(const Hierarchy& hierarchy, const Element& side, const Box& box) {
  if (box.lo.x > box.hi.x) return false;
  const dvec3 n = hierarchy.normal(side);
  const dvec3 far_corner(n.x > 0.0 ? box.hi.x : box.lo.x, n.y > 0.0 ? box.hi.y : box.lo.y,
                         n.z > 0.0 ? box.hi.z : box.lo.z);
  return glm::dot(n, far_corner - hierarchy.centre(side)) > 0.0;
}

}  // namespace

double extent_correction(const ClusterNode& receiver, const ClusterNode& emitter) {
  const dvec3 r = receiver.centre - emitter.centre;
  const dvec3 u = emitter.axis, v = receiver.axis;
  const double rho2 = glm::dot(r, r), p = glm::dot(u, r), q = glm::dot(v, r);
  const double kernel = -p * q / (std::numbers::pi * rho2 * rho2);
  if (!(kernel > 0.0)) return 1.0;
  const dvec3 w = q * u + p * v;
  const glm::dmat3 hessian =
      (-(glm::outerProduct(u, v) + glm::outerProduct(v, u)) / (rho2 * rho2) +
       4.0 * (glm::outerProduct(w, r) + glm::outerProduct(r, w)) / (rho2 * rho2 * rho2) +
       4.0 * p * q * glm::dmat3(1.0) / (rho2 * rho2 * rho2) -
       24.0 * p * q * glm::outerProduct(r, r) / (rho2 * rho2 * rho2 * rho2)) /
      std::numbers::pi;
  const glm::dmat3 spread = receiver.covariance_matrix() + emitter.covariance_matrix();
  double trace = 0.0;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) trace += hessian[i][j] * spread[j][i];
  // Beyond a factor of two the expansion is no guide (clusters this near are never linked).
  return std::clamp(1.0 + 0.5 * trace / kernel, 0.5, 2.0);
}

namespace {

// The light of every node from each side's luminance (`sent(element)`).
template <typename Sent>
ClusterLighting lighting_of(const ClusterTree& tree, const Hierarchy& hierarchy, const Sent& sent) {
  const auto& nodes = tree.nodes();
  ClusterLighting out;
  out.nodes.resize(nodes.size());
  out.flux_prefix.assign(tree.sides().size() + 1, 0.0);
  for (size_t i = 0; i < tree.sides().size(); ++i) {
    const std::int32_t side = tree.sides()[i];
    out.flux_prefix[i + 1] = out.flux_prefix[i] + sent(side) * hierarchy.element(side).area;
  }
  for (size_t i = nodes.size(); i-- > 0;) {  // children come after their parent
    const ClusterNode& node = nodes[i];
    ClusterLight& l = out.nodes[i];
    if (node.is_leaf()) {
      const double luminance = sent(tree.sides()[node.first]);
      l = {static_cast<float>(out.flux_prefix[node.first + 1] - out.flux_prefix[node.first]),
           static_cast<float>(luminance)};
    } else {
      const ClusterLight& a = out.nodes[static_cast<size_t>(node.child[0])];
      const ClusterLight& b = out.nodes[static_cast<size_t>(node.child[1])];
      l = {a.flux + b.flux, std::max(a.peak, b.peak)};
    }
  }
  return out;
}

}  // namespace

ClusterLighting estimated_cluster_light(const ClusterTree& tree, const Hierarchy& hierarchy,
                                        double radiance) {
  return lighting_of(tree, hierarchy, [&](std::int32_t side) {
    const Element& e = hierarchy.element(side);
    const double emitted = luminance(hierarchy.emission(e));
    return emitted > 0.0 ? emitted : luminance(hierarchy.reflectance(e)) * radiance;
  });
}

InitialLinks link_clusters(const ClusterTree& tree, const Hierarchy& hierarchy,
                           const RayScene& scene, const ClusterCriterion& criterion,
                           const std::function<bool()>& cancelled,
                           const std::function<void(double)>& progress) {
  if (tree.root() == kNone) return {};
  const std::vector<SideSample> sides = side_samples(tree, hierarchy);
  const Walk walk{tree, hierarchy, sides, scene, criterion};
  return walk_from(walk, {{tree.root(), tree.root()}}, true, cancelled, progress);
}

bool cluster_link_too_coarse(const ClusterTree& tree, const Hierarchy&, const ClusterLink& link,
                             const ClusterCriterion& criterion) {
  const ClusterNode& rx = tree.node(link.receiver);
  const ClusterNode& ry = tree.node(link.emitter);
  const Judgement j = judge(rx, ry, link.emitter, glm::length(rx.centre - ry.centre), criterion);
  return !may_link(j, criterion) ||
         ((link.isotropic || link.spherical) && !faint(j.light, criterion)) ||
         ray_verdict(j, criterion, link.visibility, rx.is_leaf()) != RayVerdict::Link;
}

InitialLinks split_cluster_links(const ClusterTree& tree, const Hierarchy& hierarchy,
                                 const RayScene& scene, const ClusterCriterion& criterion,
                                 std::span<const ClusterLink> links,
                                 const std::function<bool()>& cancelled) {
  if (links.empty()) return {};
  const std::vector<SideSample> sides = side_samples(tree, hierarchy);
  const Walk walk{tree, hierarchy, sides, scene, criterion};
  // The criterion no longer takes the pair: walking from it splits it.
  std::vector<Pair> start;
  start.reserve(links.size());
  for (const ClusterLink& l : links) start.emplace_back(l.receiver, l.emitter);
  return walk_from(walk, std::move(start), false, cancelled, {});
}

void mark_cluster_receivers(const ClusterTree& tree, const Hierarchy& hierarchy,
                            std::span<const ClusterLink> links, std::vector<std::uint8_t>& mark) {
  const std::vector<Box> from = senders(tree, links);
  for (size_t i = 0; i < tree.nodes().size(); ++i) {
    if (!tree.nodes()[i].is_leaf()) continue;
    const std::int32_t side = tree.sides()[tree.nodes()[i].first];
    if (faces_senders(hierarchy, hierarchy.element(side), from[i]))
      mark[static_cast<size_t>(side)] = 1;
  }
}

void sort_by_receiver(std::vector<ClusterLink>& links) {
  std::sort(links.begin(), links.end(), [](const ClusterLink& a, const ClusterLink& b) {
    return a.receiver < b.receiver || (a.receiver == b.receiver && a.emitter < b.emitter);
  });
}

void ClusterGather::operator()(const ClusterTree& tree, const std::vector<ClusterLink>& links,
                               const Hierarchy& hierarchy, const std::vector<Rgb>& radiance,
                               std::vector<SampleRgb>& gathered) {
  const auto& nodes = tree.nodes();
  power_.assign(nodes.size(), ChannelVectors{});
  flux_.assign(nodes.size(), Rgb(0.0));
  lighting_ = lighting_of(tree, hierarchy, [&](std::int32_t side) {
    return std::max(0.0, luminance(radiance[static_cast<size_t>(side)]));
  });
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
      flux_[i] = l * e.area;
    } else {
      const auto a = static_cast<size_t>(node.child[0]), b = static_cast<size_t>(node.child[1]);
      for (size_t c = 0; c < 3; ++c) p[c] = power_[a][c] + power_[b][c];
      flux_[i] = flux_[a] + flux_[b];
    }
  }
  // Each receiving cluster's S and G from its links (runs of one receiver, in parallel).
  received_.assign(nodes.size(), Received{});
  std::vector<size_t> runs;
  for (size_t i = 0; i < links.size(); ++i)
    if (i == 0 || links[i].receiver != links[i - 1].receiver) runs.push_back(i);
  runs.push_back(links.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, runs.size() - 1), [&](const auto& range) {
    for (size_t k = range.begin(); k != range.end(); ++k) {
      Received& to = received_[static_cast<size_t>(links[runs[k]].receiver)];
      glm::dmat3 change[3] = {glm::dmat3(0.0), glm::dmat3(0.0), glm::dmat3(0.0)};
      for (size_t i = runs[k]; i < runs[k + 1]; ++i) {
        const ClusterLink& link = links[i];
        const dvec3 r = tree.node(link.receiver).centre - tree.node(link.emitter).centre;
        const double d2 = glm::dot(r, r);
        const double k4 = link.transfer() / (std::numbers::pi * d2 * d2);
        const Rgb& f = flux_[static_cast<size_t>(link.emitter)];
        const double shown = static_cast<double>(link.shown) / std::sqrt(d2);
        const ChannelVectors isotropic{f.x * shown * r, f.y * shown * r, f.z * shown * r};
        const ChannelVectors& p =
            link.isotropic ? isotropic : power_[static_cast<size_t>(link.emitter)];
        if (link.spherical) {
          // Light from u = -w of H = i (n . u) for a side facing it.
          const dvec3 u = -r / std::sqrt(d2);
          const std::array<double, 9> y = harmonics(u);
          for (size_t c = 0; c < 3; ++c) {
            const double intensity = k4 * glm::dot(p[c], r) * std::sqrt(d2);
            for (size_t m = 0; m < 9; ++m)
              to.harmonics[c][m] += static_cast<float>(intensity * y[m]);
          }
          continue;
        }
        for (size_t c = 0; c < 3; ++c) {
          const double pr = glm::dot(p[c], r);
          // H = -k4 (P . r)(n . r); its change with x at fixed n (see the header).
          to.at_centre[c] -= k4 * pr * r;
          change[c] += k4 * (4.0 * pr / d2 * glm::outerProduct(r, r) - glm::outerProduct(r, p[c]) -
                             pr * glm::dmat3(1.0));
        }
      }
      for (size_t c = 0; c < 3; ++c) to.change[c] = glm::mat3(change[c]);
    }
  });
  // Down the tree: each child reads its parent's field at its own centre.
  for (size_t i = 0; i < nodes.size(); ++i) {
    const ClusterNode& node = nodes[i];
    if (node.is_leaf()) continue;
    const Received& from = received_[i];
    for (std::int32_t child : node.child) {
      Received& to = received_[static_cast<size_t>(child)];
      const dvec3 offset = tree.node(child).centre - node.centre;
      for (size_t c = 0; c < 3; ++c) {
        to.at_centre[c] += from.at_centre[c] + dvec3(from.change[c] * glm::vec3(offset));
        to.change[c] += from.change[c];
        for (size_t m = 0; m < 9; ++m) to.harmonics[c][m] += from.harmonics[c][m];
      }
    }
  }
  // Each side at its samples, through its own normal.
  const std::vector<Box> from = senders(tree, links);
  gathered.assign(hierarchy.root_count(), SampleRgb{});
  tbb::parallel_for(tbb::blocked_range<size_t>(0, nodes.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const ClusterNode& node = nodes[i];
      if (!node.is_leaf()) continue;
      const Received& field = received_[i];
      const std::int32_t side = tree.sides()[node.first];
      const Element& e = hierarchy.element(side);
      if (!faces_senders(hierarchy, e, from[i])) continue;
      const dvec3 n = hierarchy.normal(e);
      dvec3 at[kMaxSamples];
      const int count = hierarchy.samples(e, at);
      SampleRgb& out = gathered[static_cast<size_t>(side)];
      const std::array<double, 9> y = harmonics(n);
      Rgb spherical(0.0);
      for (int c = 0; c < 3; ++c) {
        double irradiance = 0.0;
        for (size_t m = 0; m < 9; ++m)
          irradiance += kClampedCosine[m] *
                        static_cast<double>(field.harmonics[static_cast<size_t>(c)][m]) * y[m];
        spherical[c] = std::max(0.0, irradiance);
      }
      for (int s = 0; s < count; ++s) {
        const glm::vec3 offset(at[s] - node.centre);
        for (int c = 0; c < 3; ++c) {
          const double h = glm::dot(n, field.at_centre[static_cast<size_t>(c)]) +
                           glm::dot(glm::vec3(n), field.change[static_cast<size_t>(c)] * offset);
          out[static_cast<size_t>(s)][c] = std::max(0.0, h) + spherical[c];
        }
      }
    }
  });
}

std::size_t ClusterGather::memory_bytes() const {
  return power_.capacity() * sizeof(ChannelVectors) + flux_.capacity() * sizeof(Rgb) +
         lighting_.nodes.capacity() * sizeof(ClusterLight) +
         lighting_.flux_prefix.capacity() * sizeof(double) +
         received_.capacity() * sizeof(Received);
}

}  // namespace radiosity
