#include "core/solve/energy_balance.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "core/hierarchy/emitter_shape.h"

namespace radiosity {
namespace {

// Bounds on the corrections: they fix a few per cent; anything beyond is a
// part whose closure or delivery is too poorly known to trust.
constexpr double kLeafScaleMin = 0.5, kLeafScaleMax = 2.0;
constexpr double kRootScaleMin = 0.8, kRootScaleMax = 1.25;
constexpr double kDownScaleMin = 0.9, kDownScaleMax = 1.1;
// Below this share of its hemisphere from its ancestors, a sample's closure
// says too little about their links to correct them.
constexpr double kMinDownCoverage = 0.05;
// Only where a surface sees nothing but linked surfaces is its closure known
// to be smooth (1 in a closed room, to the links' energy corrections); near an
// opening or a black surface it varies as fast as the far links it would
// correct (correcting to its interpolation made an open Cornell box 4 % too
// bright).
constexpr double kClosed = 1.0 - 1e-3;
// Up to this share of escaping rays (ten in 2,048) the ray pass's closure of
// a top-level element is blended in (set_escaped); beyond, its leaves'
// closure varies too much over it (a wall beside a window) for one number:
// at 0.1, the sun through a window agreed 0.5 to 0.8 % worse with Cycles.
constexpr double kTrustRays = 0.005;

using SampleWeights = std::array<double, kMaxSamples>;

// Per element e, the weights w with which the light a link leaves at e's
// samples (values v) is gathered by the leaves below once pushed down to them
// and scaled there by the receiving correction (`down`, per leaf sample): what
// they gather in all is sum_k w[k] v[k] (linear: push/pull's interpolation,
// area for area, then the leaves' averages). A leaf's own links are not scaled;
// for them its plain average holds.
std::vector<SampleWeights> gathering_weights(const Hierarchy& h,
                                             const std::vector<SampleScale>& down) {
  const auto& elements = h.elements();
  std::vector<SampleWeights> w(elements.size(), SampleWeights{});
  // Pushing v + kLift instead of v keeps the interpolation's bubble above zero
  // (where push_to_children clamps); the lift pushes down as itself.
  constexpr double kLift = 16.0;
  for (size_t e = elements.size(); e-- > 0;) {  // children come after their parent
    const Element& x = elements[e];
    const int samples = x.sample_count();
    if (x.is_leaf()) {
      const AverageWeights average = h.average_weights(x);
      for (int k = 0; k < samples; ++k)
        w[e][static_cast<size_t>(k)] = x.area * average[static_cast<size_t>(k)] *
                                       static_cast<double>(down[e][static_cast<size_t>(k)]);
      continue;
    }
    for (int k = 0; k < samples; ++k) {
      SampleRgb lifted{};
      for (int j = 0; j < samples; ++j)
        lifted[static_cast<size_t>(j)] = Rgb(j == k ? 1.0 + kLift : kLift);
      const std::array<SampleRgb, 4> children = push_to_children(h, x, lifted);
      double sum = 0.0;
      for (size_t c = 0; c < 4; ++c) {
        const auto child = static_cast<size_t>(x.first_child) + c;
        for (int j = 0; j < samples; ++j)
          sum += w[child][static_cast<size_t>(j)] * (children[c][static_cast<size_t>(j)].x - kLift);
      }
      w[e][static_cast<size_t>(k)] = sum;
    }
  }
  return w;
}

// Per element, the fraction of its light that its own links deliver, as a
// density over its area (a split emitter's share goes to its children as the
// link's emitter shape says), then summed down to the leaves: D_l. A link
// delivers what its receiver's leaves gather from it, the receiving
// correction included (`gathering`, gathering_weights): counted without it,
// the light that correction adds or takes away was made or lost at every
// bounce (a closed white room with a Blender area light and a box, at
// reflectance 0.99: 13 % too bright).
std::vector<double> delivered_fractions(const Hierarchy& h, const std::vector<Link>& links,
                                        const std::vector<SampleWeights>& gathering,
                                        const ClusterTree& tree,
                                        const std::vector<ClusterLink>& far) {
  const auto& elements = h.elements();
  std::vector<double> delivered(elements.size(), 0.0);
  for (const Link& l : links) {
    const Element& p = h.element(l.receiver);
    const Element& q = h.element(l.emitter);
    SampleRgb f{};
    for (size_t s = 0; s < kMaxSamples; ++s) f[s] = Rgb(static_cast<double>(l.form_factor[s]));
    double power = p.area * h.average(p, f).x;  // A_p F_pq = A_q F_qp
    if (!p.is_leaf()) {
      power = 0.0;
      for (int k = 0; k < p.sample_count(); ++k)
        power += gathering[static_cast<size_t>(l.receiver)][static_cast<size_t>(k)] *
                 static_cast<double>(l.form_factor[static_cast<size_t>(k)]);
    }
    if (q.is_leaf() || !shape_computed(l.emitter_shape)) {
      delivered[static_cast<size_t>(l.emitter)] += power / q.area;
      continue;
    }
    double weights = 0.0;
    for (_Float16 w : l.emitter_shape) weights += static_cast<double>(w);
    if (!(weights > 0.0)) {
      delivered[static_cast<size_t>(l.emitter)] += power / q.area;
      continue;
    }
    for (int c = 0; c < 4; ++c) {
      const std::int32_t child = q.first_child + c;
      delivered[static_cast<size_t>(child)] +=
          power * static_cast<double>(l.emitter_shape[static_cast<size_t>(c)]) / weights /
          h.element(child).area;
    }
  }
  if (!far.empty()) {
    // A cluster link delivers to its receiving cluster X from each side q of
    // the emitter cluster V (n_q . w) A_q (-N_X . w) / (pi d^2) per unit
    // radiance, N_X = sum of A n over X (every side of X faces the emitter):
    // per unit area of q that is n_q . v, v summed down the emitter's tree.
    // From an isotropic emitter every side delivers alike per unit area,
    // V shown (-N_X . w) / (pi d^2): u, summed down likewise.
    const auto& nodes = tree.nodes();
    std::vector<dvec3> v(nodes.size(), dvec3(0.0));
    std::vector<double> u(nodes.size(), 0.0);
    for (const ClusterLink& link : far) {
      const ClusterNode& x = tree.node(link.receiver);
      const dvec3 between = x.centre - tree.node(link.emitter).centre;
      const double d2 = glm::dot(between, between);
      const dvec3 w = between / std::sqrt(d2);
      const double received = link.spherical ? static_cast<double>(link.seen) * x.area
                                             : std::max(0.0, -glm::dot(x.area_normal, w));
      const double coupling = link.transfer() / (std::numbers::pi * d2) * received;
      if (link.isotropic)
        u[static_cast<size_t>(link.emitter)] += coupling * static_cast<double>(link.shown);
      else
        v[static_cast<size_t>(link.emitter)] += coupling * w;
    }
    for (size_t i = 0; i < nodes.size(); ++i) {
      const ClusterNode& node = nodes[i];
      if (!node.is_leaf()) {
        for (std::int32_t c : node.child) {
          v[static_cast<size_t>(c)] += v[i];
          u[static_cast<size_t>(c)] += u[i];
        }
        continue;
      }
      const std::int32_t side = tree.sides()[node.first];
      delivered[static_cast<size_t>(side)] +=
          std::max(0.0, glm::dot(h.normal(h.element(side)), v[i])) + u[i];
    }
  }
  // Parents come before their children.
  for (size_t e = 0; e < elements.size(); ++e) {
    if (elements[e].parent != kNone)
      delivered[e] += delivered[static_cast<size_t>(elements[e].parent)];
  }
  return delivered;
}

Rgb send(const Hierarchy& h, std::int32_t index, const Rgb& mean, double root_scale,
         const std::vector<float>& leaf_scale, std::vector<Rgb>& sent) {
  const Element& e = h.element(index);
  Rgb value;
  if (e.is_leaf()) {
    const double k = static_cast<double>(leaf_scale[static_cast<size_t>(index)]);
    value = glm::max(root_scale * mean + k * (e.radiance - mean), Rgb(0.0));
  } else {
    glm::dvec3 sum(0.0);
    for (int c = 0; c < 4; ++c) {
      const std::int32_t child = e.first_child + c;
      sum += h.element(child).area * glm::dvec3(send(h, child, mean, root_scale, leaf_scale, sent));
    }
    value = Rgb(sum / e.area);
  }
  sent[static_cast<size_t>(index)] = value;
  return value;
}

}  // namespace

void EnergyBalance::update(const Hierarchy& h, const LinkGather& grouping, const ClusterTree& tree,
                           const std::vector<ClusterLink>& far, ClusterGather& far_gather) {
  const auto& elements = h.elements();
  const size_t n = elements.size();
  // Coverage, the form factors of every sample's links summed (its
  // ancestors' pushed down): x of all linked emitters that take up part of
  // the hemisphere (a lamp that casts no shadow, as Blender's lights, hides
  // nothing: what lies behind it is linked too), y of those that receive too
  // (reflect).
  std::vector<Rgb> partners(n);
  for (size_t e = 0; e < n; ++e) {
    const bool opaque = h.patch_of(elements[e]).occludes;
    partners[e] = Rgb(opaque ? 1.0 : 0.0, h.reflects(elements[e]) ? 1.0 : 0.0, 0.0);
  }
  const LinkGather coverage{grouping.hierarchy, grouping.links, grouping.offset, grouping.order,
                            partners};
  std::vector<SampleRgb> far_coverage;
  if (!far.empty()) far_gather(tree, far, h, partners, far_coverage);
  const std::vector<SampleRgb> at_leaves = gathered_at_leaves(h, coverage, far_coverage);

  // Closure of new elements: from the links for top-level ones (first update,
  // before any refinement), pushed down from the parent for the others, the
  // way push/pull hands down what the parent gathers (so that where a child
  // has no links of its own, its closure is what it is handed: no correction).
  const size_t known = closure_.size();
  closure_.reserve(n);  // exactly n: growth by doubling would leave up to half unused
  closure_.resize(n);
  for (size_t e = known; e < n; ++e) {
    const Element& x = elements[e];
    if (x.parent == kNone) {
      for (size_t s = 0; s < kMaxSamples; ++s)
        closure_[e][s] = static_cast<float>(at_leaves[e][s].x);
      continue;
    }
    const Element& parent = elements[static_cast<size_t>(x.parent)];
    if (static_cast<std::int32_t>(e) != parent.first_child) continue;  // siblings come together
    SampleRgb values{};
    for (size_t s = 0; s < kMaxSamples; ++s)
      values[s] = Rgb(static_cast<double>(closure_[static_cast<size_t>(x.parent)][s]));
    const std::array<SampleRgb, 4> children = push_to_children(h, parent, values);
    for (size_t c = 0; c < 4; ++c)
      for (size_t s = 0; s < kMaxSamples; ++s)
        closure_[e + c][s] = static_cast<float>(children[c][s].x);
  }

  // Per leaf sample of a closed top-level element, the factor on what the
  // ancestors push down. Whether it is closed is decided for the whole
  // top-level element (its own samples' closure), not sample by sample:
  // correcting only the samples whose closure comes out at 1 or more would
  // pick those the links' energy corrections pushed up, and make light (0.2 %
  // in a closed room with a light a hair under its ceiling).
  down_scale_.assign(n, SampleScale{1, 1, 1, 1, 1});
  std::vector<std::uint8_t> closed_root(h.root_count(), 0);
  for (size_t r = 0; r < h.root_count(); ++r) {
    const std::int32_t root = h.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (root == kNone) continue;
    const Element& x = h.element(root);
    bool closed = true;
    for (int s = 0; s < x.sample_count(); ++s)
      closed &= closure_[static_cast<size_t>(root)][static_cast<size_t>(s)] >= kClosed;
    closed_root[r] = closed ? 1 : 0;
  }
  std::vector<double> receiving(n, 0.0);  // per leaf: closure over the surfaces that reflect
  tbb::parallel_for(tbb::blocked_range<size_t>(0, n), [&](const auto& range) {
    for (size_t e = range.begin(); e != range.end(); ++e) {
      const Element& x = elements[e];
      if (!x.is_leaf() || !x.has_links) continue;
      const size_t slot = 2 * static_cast<size_t>(x.patch) + x.side;
      const bool closed = closed_root[slot] != 0;
      const auto root = static_cast<size_t>(h.root(x.patch, x.side));
      // How far the rays' closure is trusted over the links' (1: nothing escapes).
      const double escaped = root < escaped_.size() ? static_cast<double>(escaped_[root]) : 1.0;
      const double trust = std::clamp(1.0 - escaped / kTrustRays, 0.0, 1.0);
      const SampleRgb own = coverage(static_cast<std::int32_t>(e));
      SampleRgb received{};
      for (int s = 0; s < x.sample_count(); ++s) {
        const size_t k = static_cast<size_t>(s);
        const Rgb down = at_leaves[e][k] - own[k];
        double scale = 1.0;
        if (closed && down.x > kMinDownCoverage)
          scale = std::clamp((static_cast<double>(closure_[e][k]) - own[k].x) / down.x,
                             kDownScaleMin, kDownScaleMax);
        down_scale_[e][k] = static_cast<float>(scale);
        received[k] = own[k] + scale * down;
      }
      const Rgb mean = h.average(x, received);
      // At most the whole hemisphere: where the samples say more, it is the
      // energy correction of a link (link_transport) showing at a point.
      receiving[e] = trust * std::clamp(1.0 - (mean.x - mean.y) - escaped, 0.0, 1.0) +
                     (1.0 - trust) * std::min(1.0, mean.y);
    }
  });

  const std::vector<double> delivered =
      delivered_fractions(h, grouping.links, gathering_weights(h, down_scale_), tree, far);
  leaf_scale_.assign(n, 1.0f);
  std::vector<double> closed(h.root_count(), 0.0), sent(h.root_count(), 0.0);
  for (size_t e = 0; e < n; ++e) {
    const Element& l = elements[e];
    if (!l.is_leaf() || !l.has_links || !h.reflects(l)) continue;
    const double c = receiving[e];
    const double d = delivered[e];
    if (!(c > 0.0) || !(d > 0.0)) continue;
    leaf_scale_[e] = static_cast<float>(std::clamp(c / d, kLeafScaleMin, kLeafScaleMax));
    const size_t root = 2 * static_cast<size_t>(l.patch) + l.side;
    closed[root] += l.area * c;
    sent[root] += l.area * d;
  }
  root_scale_.assign(h.root_count(), 1.0f);
  for (size_t r = 0; r < h.root_count(); ++r) {
    if (sent[r] > 0.0)
      root_scale_[r] =
          static_cast<float>(std::clamp(closed[r] / sent[r], kRootScaleMin, kRootScaleMax));
  }
}

void EnergyBalance::sent_radiances(const Hierarchy& h, std::vector<Rgb>& sent) const {
  const auto& elements = h.elements();
  sent.reserve(elements.size());  // exactly: see closure_ above
  sent.resize(elements.size());
  if (leaf_scale_.size() != elements.size() || root_scale_.size() != h.root_count()) {
    // Not balanced for these elements (before the first update): as they are.
    for (size_t e = 0; e < elements.size(); ++e) sent[e] = elements[e].radiance;
    return;
  }
  tbb::parallel_for(tbb::blocked_range<size_t>(0, h.root_count()), [&](const auto& range) {
    for (size_t r = range.begin(); r != range.end(); ++r) {
      const std::int32_t root = h.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
      if (root != kNone)
        send(h, root, h.element(root).radiance, static_cast<double>(root_scale_[r]), leaf_scale_,
             sent);
    }
  });
}

std::size_t EnergyBalance::memory_bytes() const {
  return (closure_.capacity() + down_scale_.capacity()) * sizeof(SampleScale) +
         (leaf_scale_.capacity() + root_scale_.capacity()) * sizeof(float);
}

}  // namespace radiosity
