#include "core/solve/link_transport.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/patch_form_factor.h"
#include "core/geometry/polygon.h"
#include "core/solve/timing.h"
#include "core/visibility/sampled_visibility.h"
#include "core/visibility/visible_polygon.h"

namespace radiosity {

namespace {

// Some corner of `polygon` lies strictly in front of the plane (point, normal),
// by more than rounding relative to the sizes involved.
bool any_in_front(const dvec3* polygon, int count, const dvec3& point, const dvec3& normal,
                  double tolerance) {
  for (int k = 0; k < count; ++k) {
    if (glm::dot(normal, polygon[k] - point) > tolerance) return true;
  }
  return false;
}

double distance_to_segment(const dvec3& p, const dvec3& a, const dvec3& b) {
  const dvec3 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}

// Distance from p to a planar convex polygon (counter-clockwise about its normal).
double distance_to_polygon(const dvec3& p, std::span<const dvec3> polygon) {
  const size_t k = polygon.size();
  const dvec3 normal =
      glm::normalize(glm::cross(polygon[1] - polygon[0], polygon[k - 1] - polygon[0]));
  bool inside = true;
  double edge = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < k; ++i) {
    const dvec3& a = polygon[i];
    const dvec3& b = polygon[(i + 1) % k];
    inside = inside && glm::dot(glm::cross(b - a, p - a), normal) >= 0.0;
    edge = std::min(edge, distance_to_segment(p, a, b));
  }
  return inside ? std::abs(glm::dot(p - polygon[0], normal)) : edge;
}

}  // namespace

bool elements_face_each_other(const Hierarchy& h, const Element& receiver, const Element& emitter) {
  dvec3 p[4], q[4];
  const int np = h.corners(receiver, p), nq = h.corners(emitter, q);
  const double tolerance = 1e-9 * (h.diameter(receiver) + h.diameter(emitter));
  return any_in_front(q, nq, p[0], h.normal(receiver), tolerance) &&
         any_in_front(p, np, q[0], h.normal(emitter), tolerance);
}

namespace {

// The corners and samples of a link's two elements.
struct LinkEnds {
  dvec3 receiver_corners[4], emitter_corners[4], x[kMaxSamples];
  int nr = 0, ne = 0, ns = 0;
  dvec3 n{0.0};
  std::span<const dvec3> receiver_polygon() const {
    return {receiver_corners, static_cast<size_t>(nr)};
  }
  std::span<const dvec3> emitter_polygon() const {
    return {emitter_corners, static_cast<size_t>(ne)};
  }
};

LinkEnds link_ends(const Hierarchy& h, const Element& receiver, const Element& emitter) {
  LinkEnds e;
  e.nr = h.corners(receiver, e.receiver_corners);
  e.ne = h.corners(emitter, e.emitter_corners);
  e.ns = h.samples(receiver, e.x);
  e.n = h.normal(receiver);
  return e;
}

// Form factor and gradient at each receiver sample.
struct SampleValues {
  double value[kMaxSamples] = {};
  dvec3 grad[kMaxSamples] = {};
  // The unoccluded F where the visibility computation gave it (-1: not known),
  // so the energy correction need not compute it again.
  double open[kMaxSamples];
  SampleValues() { std::fill(std::begin(open), std::end(open), -1.0); }
};

std::vector<Triangle>& gather_candidates(const OccluderScene& scene, const ShaftCulling& culling) {
  thread_local std::vector<Triangle> candidates;
  candidates.clear();
  for (std::uint32_t t : culling.candidates) candidates.push_back(scene.triangles[t]);
  return candidates;
}

// Nearest and largest first: seen from a point, an occluder's image grows as
// its area over its squared distance. Subtracted first, the large images
// leave fewer visible pieces for the rest to cut, and where they hide the
// whole emitter the rest are never projected. Two triangles that share an
// edge (a mesh quad split in two, which the visible polygon takes as one
// occluder when they come one after the other) move together.
void order_occluders(std::vector<Triangle>& candidates, const dvec3& from) {
  struct Unit {
    double size;
    std::uint32_t first, count;
  };
  const auto share_edge = [](const Triangle& a, const Triangle& b) {
    int same = 0;
    for (const dvec3& p : a.v)
      for (const dvec3& q : b.v) same += p == q ? 1 : 0;
    return same >= 2;
  };
  thread_local std::vector<Unit> units;
  thread_local std::vector<Triangle> ordered;
  units.clear();
  for (std::uint32_t i = 0; i < candidates.size();) {
    const std::uint32_t count =
        i + 1 < candidates.size() && share_edge(candidates[i], candidates[i + 1]) ? 2 : 1;
    double size = 0.0;
    for (std::uint32_t k = i; k < i + count; ++k) {
      const Triangle& t = candidates[k];
      const dvec3 centre = (t.v[0] + t.v[1] + t.v[2]) / 3.0;
      const double area = glm::length(glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0]));
      size += area / std::max(glm::dot(centre - from, centre - from), 1e-300);
    }
    units.push_back({size, i, count});
    i += count;
  }
  std::stable_sort(units.begin(), units.end(),
                   [](const Unit& a, const Unit& b) { return a.size > b.size; });
  ordered.clear();
  for (const Unit& u : units)
    ordered.insert(ordered.end(), candidates.begin() + u.first,
                   candidates.begin() + u.first + u.count);
  std::swap(candidates, ordered);
}

// Candidate occluders past which shadow rays go through Embree rather than
// being tested one by one (the crossover measured near 35 candidates).
constexpr std::size_t kRayCrossover = 32;

FormFactorGradient unoccluded(const LinkEvaluator& evaluator, const dvec3& x, const dvec3& n,
                              std::span<const dvec3> emitter) {
  return oracle_needs_gradient(evaluator.oracle)
             ? form_factor_gradient(x, n, emitter)
             : FormFactorGradient{form_factor(x, n, emitter), dvec3(0.0)};
}

// A point's form factor through shadow rays: tested against the candidates
// when few, through Embree's scene when many or when the list stopped at the
// crossover. The seed varies with the point so that neighbours do not share
// one stratification pattern.
FormFactorGradient shadowed_by_rays(const LinkEvaluator& evaluator, const Element& receiver,
                                    const Element& emitter, const dvec3& x, const dvec3& n,
                                    std::span<const dvec3> emitter_polygon,
                                    std::span<const Triangle> candidates, bool truncated,
                                    std::uint64_t seed, double* open) {
  const SampledVisibilityOptions options{evaluator.rays, seed};
  const Hierarchy& h = evaluator.hierarchy;
  return truncated || candidates.size() > kRayCrossover
             ? sampled_form_factor_gradient(x, n, emitter_polygon, *evaluator.occluders.rays,
                                            options, h.patch_of(receiver).surface,
                                            h.patch_of(emitter).surface, open)
             : sampled_form_factor_gradient(x, n, emitter_polygon, candidates, options, open);
}

// The five samples integrate F over the receiver only approximately, badly
// near an emitter (F grows quickly towards it): a link would move more or less
// light than the two patches exchange (10 to 25 % at coarse levels, so energy
// was not conserved). The exact patch form factor F_pq fixes the samples'
// average (the interpolant's, which is what the receiver absorbs). The fix is
// additive, delta = F_pq - average: at a sample that sees all of a closed scene
// through links of one level, the form factors still sum to one (the deltas of
// those links sum to zero), so the furnace stays exact. It goes only to the
// samples in front of the emitter's plane (F_pq counts only that part of the
// receiver; samples behind it stay dark, and the others carry the whole
// delta). A sample can end a little below zero where F falls steeply; the
// gather's sum is what matters and the output clamps at zero. Where some
// sample is partly hidden, the samples are scaled by F_pq / average instead
// (see below).

// What the 3 x 3 grid of the energy correction (below) is shadowed by: the
// link's candidate occluders, exactly, or by shadow rays at the points where
// the link's light is faint (faint_samples.h), as at the samples.
struct GridVisibility {
  const LinkEvaluator& evaluator;
  const Element& receiver;
  const Element& emitter;
  std::span<const Triangle> candidates;
  std::uint64_t* points_faint;  // counts the points that took rays
};

// The five samples' visible share is poor where they sit on the outline of
// something close to the receiver (contact.h insets them off it, so they are
// no longer representative of the corners' regions: the ceiling around a
// light a hair under it delivered 3 % less than its closure). On elements
// with such a sample, with exact visibility, the share comes from a 3 x 3 grid
// of points over the element instead (a 4 x 4 grid cost 16 % of a furnished
// room's solve and agreed with Cycles no better: test_contact, every case
// within 0.1 %).
double grid_visible_share(const LinkEnds& ends, int corner_count, const GridVisibility& grid) {
  const LinkEvaluator& evaluator = grid.evaluator;
  const Hierarchy& h = evaluator.hierarchy;
  const bool may_be_faint = evaluator.faint && !evaluator.faint->empty();
  const std::int32_t receiver_side = h.root(grid.receiver.patch, grid.receiver.side);
  const std::int32_t emitter_side = h.root(grid.emitter.patch, grid.emitter.side);
  double visible = 0.0, open = 0.0;
  const dvec3* c = ends.receiver_corners;
  constexpr int kGrid = 3;
  for (int i = 0; i < kGrid; ++i) {
    for (int j = 0; j < kGrid; ++j) {
      const dvec3 x = grid_point(c, corner_count, i, j, kGrid);
      double unoccluded = 0.0;
      if (may_be_faint && evaluator.faint->faint(receiver_side, emitter_side,
                                                 form_factor(x, ends.n, ends.emitter_polygon()))) {
        // Seeds past the samples' (0 .. kMaxSamples - 1).
        const auto seed = static_cast<std::uint64_t>(kMaxSamples + i * kGrid + j);
        visible +=
            shadowed_by_rays(evaluator, grid.receiver, grid.emitter, x, ends.n,
                             ends.emitter_polygon(), grid.candidates, false, seed, &unoccluded)
                .value;
        ++*grid.points_faint;
      } else {
        visible +=
            visible_form_factor(x, ends.n, ends.emitter_polygon(), grid.candidates, &unoccluded);
      }
      open += unoccluded;
    }
  }
  return open > 0.0 ? visible / open : -1.0;
}

// The interpolant's average of per-sample values: what the receiver gathers.
double sample_average(const AverageWeights& weights, int corner_count, const double* value) {
  double sum = 0.0;
  for (int s = 0; s <= corner_count; ++s) sum += weights[static_cast<size_t>(s)] * value[s];
  return sum;
}

// Returns how much more light occluders hide at one sample than at another
// (the largest open-minus-visible form factor over the samples less the
// smallest): a shadow's edge lies between them, and the light beside it
// reaches about the open value, which the samples' reconstruction cannot show.
double conserve_energy(const Element& receiver, const AverageWeights& weights, const LinkEnds& ends,
                       bool unoccluded, SampleValues& values, const GridVisibility* grid) {
  std::array<Rgb, kMaxSamples> open{}, in_front{};
  double visible[kMaxSamples] = {};
  double hidden_most = 0.0, hidden_least = std::numeric_limits<double>::infinity();
  for (int s = 0; s < ends.ns; ++s) {
    const double f = unoccluded ? values.value[s]
                     : values.open[s] >= 0.0
                         ? values.open[s]
                         : form_factor(ends.x[s], ends.n, ends.emitter_polygon());
    open[static_cast<size_t>(s)] = Rgb(f);
    in_front[static_cast<size_t>(s)] = Rgb(f > 0.0 ? 1.0 : 0.0);
    visible[s] = f > 0.0 ? std::clamp(values.value[s] / f, 0.0, 1.0) : 0.0;
    const double hidden = std::max(0.0, f - values.value[s]);
    hidden_most = std::max(hidden_most, hidden);
    hidden_least = std::min(hidden_least, hidden);
  }
  const double shadow_contrast = hidden_most - std::min(hidden_least, hidden_most);
  const double average = Interpolant::average(weights, receiver.corner_count, open).x;
  const double front = Interpolant::average(weights, receiver.corner_count, in_front).x;
  // 1e-6: far pairs need fewer quadrature points than the kernel's default
  // (7 x 7 instead of 5 x 5 at a gap of three radii for 1e-8, which changed
  // no energy test's result beyond 1e-7).
  const double exact = patch_form_factor(ends.receiver_polygon(), ends.emitter_polygon(), 1e-6);
  if (!(average > 0.0) || !(exact >= 0.0) || !(front > 0.0)) return shadow_contrast;
  bool all_seen = true;
  for (int s = 0; s < ends.ns; ++s)
    all_seen &= open[static_cast<size_t>(s)].x <= 0.0 || visible[s] >= 1.0 - 1e-9;
  if (!all_seen) {
    // Part hidden: the shift that corrects the open samples' average could
    // outweigh what the visible samples carry (a floor whose centre sample is
    // under a box would go below zero and lose all its light). Scale them
    // instead: the link carries F_pq times the samples' visible share.
    double scale = exact / average;
    if (grid) {
      const double share = grid_visible_share(ends, receiver.corner_count, *grid);
      std::array<Rgb, kMaxSamples> seen{};
      for (int s = 0; s < ends.ns; ++s) seen[static_cast<size_t>(s)] = Rgb(values.value[s]);
      const double seen_average = Interpolant::average(weights, receiver.corner_count, seen).x;
      if (share >= 0.0 && seen_average > 0.0) scale = exact * share / seen_average;
    }
    for (int s = 0; s < ends.ns; ++s) values.value[s] *= scale;
    return shadow_contrast;
  }
  for (int s = 0; s < ends.ns; ++s) values.value[s] += (exact - average) * visible[s] / front;
  return shadow_contrast;
}

// Stores the sample form factors and the oracle's geometric criterion; false
// when no sample sees the emitter. `by_rays`: every sample took shadow rays,
// and the candidates may stop at the crossover (no exact grid from them).
bool finish(const LinkEvaluator& evaluator, Link& link, const LinkEnds& ends, SampleValues values,
            bool unoccluded, bool by_rays, LinkTimings& timings,
            std::span<const Triangle> candidates) {
  const Hierarchy& hierarchy = evaluator.hierarchy;
  const Element& receiver = hierarchy.element(link.receiver);
  const double* value = values.value;
  const dvec3* grad = values.grad;
  bool any = false;
  for (int s = 0; s < ends.ns; ++s) any |= value[s] > 0.0;
  if (!any) return false;

  // A receiver sample touching the emitter's outline (elements meeting at an
  // edge or a corner) sees the contact itself: at a vertex a value that depends
  // on the direction of approach and an unbounded gradient (MATH.md s3), on an
  // edge a slope set by the emitter's width, steep for thin emitters (a table
  // leg on the floor). No element size makes the radiance linear there, so the
  // oracle judges the element by its other samples; the sample still gathers.
  // The same next to an occluder touching the receiver (a box's wall at its
  // foot on the floor, a leg under a table top): the shadow's edge starts at
  // the sample, whose gradient is then near-singular.
  const auto start = Clock::now();
  const double contact = 1e-5 * hierarchy.diameter(receiver);
  dvec3 oracle_x[kMaxSamples], oracle_grad[kMaxSamples];
  double oracle_value[kMaxSamples];
  bool at_emitter[kMaxSamples], at_occluder[kMaxSamples];
  // Only occluders whose bounding boxes come within `contact` of the samples'
  // can touch one: the box test spares most of the distance computations.
  dvec3 low = ends.x[0], high = ends.x[0];
  for (int s = 1; s < ends.ns; ++s)
    low = glm::min(low, ends.x[s]), high = glm::max(high, ends.x[s]);
  low -= dvec3(contact), high += dvec3(contact);
  thread_local std::vector<const Triangle*> close;
  close.clear();
  for (const Triangle& t : candidates) {
    const dvec3 t_low = glm::min(glm::min(t.v[0], t.v[1]), t.v[2]);
    const dvec3 t_high = glm::max(glm::max(t.v[0], t.v[1]), t.v[2]);
    if (glm::all(glm::lessThanEqual(t_low, high)) && glm::all(glm::lessThanEqual(low, t_high)))
      close.push_back(&t);
  }
  int clear = 0;
  for (int s = 0; s < ends.ns; ++s) {
    at_emitter[s] = at_occluder[s] = false;
    for (int k = 0; k < ends.ne; ++k) {
      at_emitter[s] |= distance_to_segment(ends.x[s], ends.emitter_corners[k],
                                           ends.emitter_corners[(k + 1) % ends.ne]) < contact;
    }
    for (size_t t = 0; t < close.size() && !at_emitter[s] && !at_occluder[s]; ++t)
      at_occluder[s] = distance_to_polygon(ends.x[s], close[t]->v) < contact;
    clear += at_emitter[s] || at_occluder[s] ? 0 : 1;
  }
  // An element whose corners all touch occluders (a floor between two walls
  // standing on it) is still judged by them: by its centre alone it would
  // never refine.
  const bool skip_occluder_contacts = clear >= 2;
  size_t used = 0;
  const auto use = [&](int s) {
    oracle_x[used] = ends.x[s];
    oracle_value[used] = std::max(0.0, value[s]);
    oracle_grad[used] = grad[s];
    ++used;
  };
  for (int s = 0; s < ends.ns; ++s) {
    if (!at_emitter[s] && !(at_occluder[s] && skip_occluder_contacts)) use(s);
  }
  const size_t with_tangents = used;
  // Noticeable also reads the contact samples' values, which are
  // finite: the light's rise towards a contact is what the mesh must show.
  if (evaluator.oracle == Oracle::Noticeable) {
    for (int s = 0; s < ends.ns; ++s) {
      if (at_emitter[s] || (at_occluder[s] && skip_occluder_contacts)) use(s);
    }
  }
  timings.oracle += seconds_since(start);

  // What is gathered carries the right total; the oracle judges the samples
  // as measured (copied above), Noticeable also by how far this moved them.
  const auto conserve_start = Clock::now();
  for (int s = 0; s < ends.ns; ++s) values.value[s] = std::max(0.0, values.value[s]);
  const bool judges_correction = evaluator.oracle == Oracle::Noticeable;
  const AverageWeights weights = hierarchy.average_weights(receiver);
  const double before =
      judges_correction ? sample_average(weights, receiver.corner_count, values.value) : 0.0;
  const bool grid = !unoccluded && !by_rays && hierarchy.samples_inset(receiver);
  const GridVisibility grid_visibility{evaluator, receiver, hierarchy.element(link.emitter),
                                       candidates, &timings.grid_points_faint};
  const double shadow_contrast = conserve_energy(receiver, weights, ends, unoccluded, values,
                                                 grid ? &grid_visibility : nullptr);
  for (int s = 0; s < ends.ns; ++s)
    link.form_factor[static_cast<size_t>(s)] = static_cast<float>(values.value[s]);
  timings.form_factors += seconds_since(conserve_start);

  const auto oracle_start = Clock::now();
  LinkSamples samples{
      std::span<const dvec3>(oracle_x, used),
      std::span<const double>(oracle_value, used),
      std::span<const dvec3>(oracle_grad, used),
      ends.n,
      receiver.area,
      hierarchy.diameter(receiver),
      resolvable_size(hierarchy.scene().total_area),
      used - with_tangents,
      judges_correction
          ? std::abs(sample_average(weights, receiver.corner_count, values.value) - before)
          : 0.0,
      shadow_contrast};
  link.oracle = with_tangents >= 1 && used >= 2
                    ? static_cast<float>(oracle_geometry(evaluator.oracle, samples) /
                                         evaluator.geometric_scale)
                    : 0.0f;
  timings.oracle += seconds_since(oracle_start);
  return true;
}

// Which samples of a link shadow rays serve, with exact visibility
// (faint_samples.h); true where all of them do.
bool faint_samples(const LinkEvaluator& evaluator, const Element& receiver, const Element& emitter,
                   const LinkEnds& ends, std::array<bool, kMaxSamples>& by_rays) {
  const Hierarchy& h = evaluator.hierarchy;
  const std::int32_t receiver_side = h.root(receiver.patch, receiver.side);
  const std::int32_t emitter_side = h.root(emitter.patch, emitter.side);
  bool all = true;
  for (int s = 0; s < ends.ns; ++s) {
    const bool faint = evaluator.faint->faint(
        receiver_side, emitter_side, form_factor(ends.x[s], ends.n, ends.emitter_polygon()));
    by_rays[static_cast<size_t>(s)] = faint;
    all = all && faint;
  }
  return all;
}

}  // namespace

bool LinkEvaluator::evaluate(Link& link, LinkTimings& timings, CornerMemo* memo) const {
  const Element& receiver = hierarchy.element(link.receiver);
  const Element& emitter = hierarchy.element(link.emitter);
  link.form_factor.fill(0.0f);
  link.oracle = 0.0f;
  if (!elements_face_each_other(hierarchy, receiver, emitter)) return false;
  const LinkEnds ends = link_ends(hierarchy, receiver, emitter);
  const std::span<const dvec3> emitter_polygon = ends.emitter_polygon();

  auto start = Clock::now();
  // Which samples shadow rays serve, before any visibility work: where all of
  // them do, the shaft is culled as sampled visibility culls it.
  std::array<bool, kMaxSamples> by_rays{};
  const bool all_by_rays = visibility == VisibilityMode::Sampled ||
                           (visibility == VisibilityMode::Exact && faint && !faint->empty() &&
                            faint_samples(*this, receiver, emitter, ends, by_rays));
  // Shadow rays need no list of occluders: past the crossover, stop looking.
  const std::size_t limit = all_by_rays ? kRayCrossover : std::numeric_limits<std::size_t>::max();
  const ShaftCulling culling =
      cull_shaft(occluders.shafts, ends.receiver_polygon(), hierarchy.patch_of(receiver).surface,
                 emitter_polygon, hierarchy.patch_of(emitter).surface, limit);
  timings.visibility += seconds_since(start);
  if (culling.visibility == ShaftVisibility::hidden) return false;

  start = Clock::now();
  std::vector<Triangle>& candidates = gather_candidates(occluders.shafts, culling);
  if (!all_by_rays && visibility == VisibilityMode::Exact)
    order_occluders(candidates, hierarchy.centre(receiver));
  SampleValues values;
  // A corner is shared with siblings only if it is far from the emitter: close
  // to it, the sample's millionth offset towards its own element's centre
  // matters (at a contact, how the light splits between two emitter children
  // depends on the direction of approach). At a tenth of the receiver's size
  // away, the offset changes F by about 1e-5 relative.
  if (memo) memo->use_emitter(link.emitter);
  const double near = 0.1 * hierarchy.diameter(receiver);
  // Samples moved off a contact line sit where their own element puts them,
  // not where a sibling's would: nothing to share.
  const bool inset = hierarchy.samples_inset(receiver);
  for (int s = 0; s < ends.ns; ++s) {
    const dvec3& x = ends.x[s];
    const bool corner = s < receiver.corner_count;
    const std::uint32_t vertex = corner ? receiver.corner[static_cast<size_t>(s)] : 0u;
    const bool shared = memo && corner && !inset && distance_to_polygon(x, emitter_polygon) > near;
    const FormFactorGradient* known = shared ? memo->find(vertex) : nullptr;
    FormFactorGradient f;
    if (known) {
      f = *known;
      ++timings.samples_shared;
    } else if (culling.visibility == ShaftVisibility::clear) {
      ++timings.samples_clear;
      f = unoccluded(*this, x, ends.n, emitter_polygon);
    } else if (visibility == VisibilityMode::Exact && !by_rays[static_cast<size_t>(s)]) {
      ++timings.samples_occluded;
      // The standard oracle reads no gradient: F alone is cheaper.
      f = oracle_needs_gradient(oracle)
              ? visible_form_factor_gradient(x, ends.n, emitter_polygon, candidates,
                                             &values.open[s])
              : FormFactorGradient{
                    visible_form_factor(x, ends.n, emitter_polygon, candidates, &values.open[s]),
                    dvec3(0.0)};
    } else {
      ++timings.samples_occluded;
      timings.samples_faint += visibility == VisibilityMode::Exact;
      f = shadowed_by_rays(*this, receiver, emitter, x, ends.n, emitter_polygon, candidates,
                           culling.truncated, static_cast<std::uint64_t>(s), &values.open[s]);
    }
    if (shared && !known) memo->add(vertex, f);
    values.value[s] = f.value;
    values.grad[s] = f.gradient;
  }
  timings.form_factors += seconds_since(start);
  return finish(*this, link, ends, values, culling.visibility == ShaftVisibility::clear,
                all_by_rays, timings, candidates);
}

void LinkEvaluator::evaluate_emitter_siblings(std::span<Link> links, LinkTimings& timings,
                                              std::span<std::uint8_t> visible) const {
  const size_t count = links.size();
  const auto one_by_one = [&] {
    for (size_t i = 0; i < count; ++i) visible[i] = evaluate(links[i], timings) ? 1 : 0;
  };
  if (visibility != VisibilityMode::Exact || count < 2 || count > 4) return one_by_one();
  const Element& receiver = hierarchy.element(links[0].receiver);
  const Element& parent = hierarchy.element(hierarchy.element(links[0].emitter).parent);
  // Where the parent's light is faint at every sample, so is each child's (a
  // part of it): their samples all take rays, one link at a time.
  std::array<bool, kMaxSamples> by_rays{};
  if (faint && !faint->empty() &&
      faint_samples(*this, receiver, parent, link_ends(hierarchy, receiver, parent), by_rays))
    return one_by_one();
  // The children that face the receiver; their polygons are the parts.
  std::array<LinkEnds, 4> ends;
  std::array<std::span<const dvec3>, 4> parts;
  std::array<size_t, 4> which{};
  size_t facing = 0;
  for (size_t i = 0; i < count; ++i) {
    links[i].form_factor.fill(0.0f);
    links[i].oracle = 0.0f;
    visible[i] = 0;
    const Element& emitter = hierarchy.element(links[i].emitter);
    if (!elements_face_each_other(hierarchy, receiver, emitter)) continue;
    ends[facing] = link_ends(hierarchy, receiver, emitter);
    parts[facing] = ends[facing].emitter_polygon();
    which[facing++] = i;
  }
  if (facing == 0) return;

  dvec3 parent_corners[4];
  const std::span<const dvec3> parent_polygon(
      parent_corners, static_cast<size_t>(hierarchy.corners(parent, parent_corners)));
  auto start = Clock::now();
  const ShaftCulling culling =
      cull_shaft(occluders.shafts, ends[0].receiver_polygon(), hierarchy.patch_of(receiver).surface,
                 parent_polygon, hierarchy.patch_of(parent).surface);
  timings.visibility += seconds_since(start);
  if (culling.visibility == ShaftVisibility::hidden) return;

  start = Clock::now();
  std::vector<Triangle>& candidates = gather_candidates(occluders.shafts, culling);
  order_occluders(candidates, hierarchy.centre(receiver));
  std::array<SampleValues, 4> values;
  const LinkEnds& shared = ends[0];  // the receiver's samples are the same for all
  for (int s = 0; s < shared.ns; ++s) {
    std::array<FormFactorGradient, 4> f;
    std::array<double, 4> open{-1.0, -1.0, -1.0, -1.0};
    if (culling.visibility == ShaftVisibility::clear) {
      timings.samples_clear += facing;
      for (size_t k = 0; k < facing; ++k) f[k] = unoccluded(*this, shared.x[s], shared.n, parts[k]);
    } else {
      ++timings.samples_occluded;
      timings.samples_shared += facing - 1;
      visible_form_factor_gradient_parts(
          shared.x[s], shared.n, parent_polygon,
          std::span<const std::span<const dvec3>>(parts.data(), facing), candidates,
          std::span<FormFactorGradient>(f.data(), facing), std::span<double>(open.data(), facing));
    }
    for (size_t k = 0; k < facing; ++k) {
      values[k].value[s] = f[k].value;
      values[k].grad[s] = f[k].gradient;
      values[k].open[s] = open[k];
    }
  }
  timings.form_factors += seconds_since(start);
  for (size_t k = 0; k < facing; ++k)
    visible[which[k]] =
        finish(*this, links[which[k]], ends[k], values[k],
               culling.visibility == ShaftVisibility::clear, false, timings, candidates)
            ? 1
            : 0;
}

}  // namespace radiosity
