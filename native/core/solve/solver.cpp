#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/hierarchy/cluster_tree.h"
#include "core/hierarchy/make_output_mesh.h"
#include "core/solve/cluster_links.h"
#include "core/solve/convergence.h"
#include "core/solve/dim_sides.h"
#include "core/solve/direct_light.h"
#include "core/solve/energy_balance.h"
#include "core/solve/gather.h"
#include "core/solve/link_batch.h"
#include "core/solve/pass_progress.h"
#include "core/solve/ray_pass.h"
#include "core/solve/refine.h"
#include "core/solve/reuse.h"
#include "core/solve/system_memory.h"
#include "core/solve/timing.h"
#include "core/solve/yield_priority.h"
#include "radiosity/solve.h"

namespace radiosity {
namespace {

// Threshold range of each oracle over quality (0, 1], log-spaced. Measured on
// a 4 x 4 x 3 m room with a ceiling light and a box (tests/native), so that the
// three oracles make similar element counts at the same quality (about 4,000 at
// 0.5) and 0.1 barely refines; see bench/ for the sweeps.
struct ThresholdRange {
  double coarse, fine;
};

// Quality 0 to 1 onto the range, log-linearly.
double log_interpolate(const ThresholdRange& range, double quality) {
  return range.coarse * std::pow(range.fine / range.coarse, std::clamp(quality, 0.0, 1.0));
}

ThresholdRange threshold_range(Oracle oracle) {
  switch (oracle) {
    case Oracle::Standard:
      return {1e-2, 1e-7};
    case Oracle::Perceptual:
      return {1.0, 4e-3};
    case Oracle::Gradient:
      return {1e-1, 2.5e-4};
    case Oracle::Noticeable:  // just noticeable differences
      return {10.0, 0.25};
  }
  return {1.0, 1e-4};
}

// Far enough apart for a cluster link: the emitter cluster's light is taken
// as if it left from its centroid, which errs more the larger it looks from
// the receiver, so finer quality asks for more distance.
double cluster_separation(const SolveOptions& options, double quality) {
  return options.cluster_separation > 0.0 ? options.cluster_separation : 2.0 + 8.0 * quality;
}

// The error in power a cluster link may make, relative to the adaptation
// radiance times the total area: the standard oracle's scale (what a link's
// light varies by over its receiver), finite at quality 0.
double cluster_threshold(double quality) {
  return log_interpolate(threshold_range(Oracle::Standard), quality);
}

// Radiance change since the last refinement when not known: refine first.
constexpr double kUnknownDrift = std::numeric_limits<double>::infinity();
// The threshold of an iteration that refines nothing.
constexpr double kNoRefinement = std::numeric_limits<double>::infinity();

// Shadow rays that measure a cluster link's visible fraction.
constexpr int kClusterRays = 16;

double gigabytes(std::size_t bytes) { return std::round(static_cast<double>(bytes) / 1e8) / 10.0; }

class Solver {
 public:
  Solver(const Scene& scene, const SolveOptions& options)
      : scene_(scene),
        options_(options),
        hierarchy_(scene),
        occluders_(make_scene_occluders(scene)),
        evaluator_{hierarchy_,         occluders_,
                   options.visibility, options.rays,
                   options.oracle,     oracle_geometric_scale(options.oracle, scene.total_area)},
        direct_(hierarchy_, occluders_, options.visibility, options.rays, options.oracle,
                oracle_geometric_scale(options.oracle, scene.total_area)),
        roots_(hierarchy_.elements().size()),
        clusters_(hierarchy_) {}

  // The whole solve.
  SolveResult run(const ProgressCallback& progress, const CancelCheck& cancel);
  // Solves again with the elements and links of the last run or relight, after
  // the scene's emission, reflectance or light colours changed (to values the
  // links already reach: SolveReuse) and with `options`' limits; refinement
  // goes on where the new radiances ask.
  // `scale`: about how much brighter the new lighting is (the start's guess).
  SolveResult relight(const SolveOptions& options, double scale, const ProgressCallback& progress,
                      const CancelCheck& cancel);
  // Whether the last run or relight completed (not cancelled or cut short by
  // the time budget): only then do its hierarchy and links stand.
  bool complete() const { return complete_; }
  const SolveOptions& options() const { return options_; }
  std::size_t memory_bytes() const { return stats_.element_bytes + stats_.link_bytes; }

 private:
  void begin(const SolveOptions& options, const ProgressCallback& progress,
             const CancelCheck& cancel);
  void solve_passes(double drift);
  SolveResult end();
  bool cancelled() const {
    if (!stopped_ && cancel_ && *cancel_ && (*cancel_)()) stopped_ = true;
    return stopped_;
  }
  double elapsed() const {
    return options_.clock ? options_.clock() - clock_start_ : seconds_since(start_);
  }
  bool out_of_time() const { return options_.time_budget && elapsed() > *options_.time_budget; }
  // Cancelled, or a refinement cut short by the time budget: the pass is
  // abandoned and the last complete one stands.
  bool pass_abandoned() const { return cancelled() || refinement_cut_short_; }

  void report(SolvePhase phase, double fraction, const SolveResult* pass_result = nullptr);
  double pass_fraction(double within) const;
  std::size_t leaves() const {  // a split makes one leaf four
    return hierarchy_.elements().size() - (hierarchy_.elements().size() - roots_) / 4;
  }
  // Quality of each pass, coarse to fine (pass 0 refines nothing: quality 0).
  std::vector<double> pass_qualities() const;
  ClusterCriterion cluster_criterion(double quality, const ClusterLighting& lighting,
                                     double adaptation) const;
  bool refine_cluster_links();
  void mark_cluster_receivers_linked();
  void count(SolveStats& stats) const;
  void look_by_rays();
  void link_initially();
  // Linking cannot finish: cancelled, out of time, or the walk's memory (the
  // process's growth since the solve began) past the memory limit.
  bool linking_stopped() const;
  void drop_links_light_cannot_reach();
  std::vector<Link> evaluate(std::vector<Link>&& candidates);
  bool refine(double threshold);
  bool refine_light_links(double threshold);
  void gather_direct_light();
  bool over_memory() const { return stats_.element_bytes + stats_.link_bytes > memory_limit_; }
  void group_links();
  void gather_far_light();
  double gather_push_pull();
  double iterate(double threshold, int max_iterations, double tolerance,
                 double drift = kUnknownDrift);
  void snapshot(double threshold);
  void track_memory();

  const Scene& scene_;
  SolveOptions options_;
  // The call's (run or relight).
  const ProgressCallback* progress_ = nullptr;
  const CancelCheck* cancel_ = nullptr;
  mutable std::atomic<bool> stopped_{false};  // read and set from worker threads
  Clock::time_point start_;
  double clock_start_ = 0.0;  // options_.clock() when the call began
  Hierarchy hierarchy_;
  SceneOccluders occluders_;
  LinkEvaluator evaluator_;
  DirectLight direct_;
  // What the oracles' values are relative to (refine()).
  DecisionScale decision_scale_;
  RefineLimits limits_;
  const std::size_t roots_;   // elements before any split: every split adds four
  std::size_t memory_limit_;  // bytes of elements and links (SolveOptions::memory_limit)
  std::vector<Link> links_;
  // Links grouped by receiver for the gather, and which links they describe.
  std::vector<std::uint32_t> offset_, order_;
  std::vector<Rgb> source_;  // radiance per element as the last gather read it (what each sends)
  EnergyBalance balance_;    // corrections of what is received and sent (energy_balance.h)
  ClusterTree clusters_;
  std::vector<ClusterLink> cluster_links_;
  ClusterGather cluster_gather_;
  // What each top-level element gathers through cluster links, at its samples.
  std::vector<SampleRgb> far_light_;
  // Light from the lights that are not surfaces: one link per leaf and light
  // that reaches it, and what each element gathers from them at its samples.
  std::vector<LightLink> light_links_;
  std::vector<SampleRgb> direct_light_;
  // Sides too dim to link, which gather by rays, and what every side gathers
  // by rays (dim_sides.h).
  DimSides dim_sides_;
  std::vector<Rgb> ray_light_;
  // With exact visibility, the samples whose light from a link is faint
  // enough for shadow rays (faint_samples.h).
  FaintSamples faint_;
  std::uint64_t light_version_ = 1, direct_version_ = 0;
  std::uint64_t links_version_ = 1, grouped_version_ = 0;
  SolveResult result_;       // the last complete pass
  bool budget_hit_ = false;  // max_elements or memory_limit reached
  mutable std::atomic<bool> memory_hit_{
      false};                          // also set by linking_stopped() from the walk's threads
  bool cut_short_ = false;             // the last evaluate_links stopped before the end
  bool refinement_cut_short_ = false;  // ... within refine(): the pass is abandoned
  std::vector<double> qualities_;      // one per pass (pass_qualities)
  int pass_ = 0, passes_ = 1;
  double fraction_ = 0.0;  // the last reported: progress never goes back
  PassProgress pass_progress_;
  double threshold_ = std::numeric_limits<double>::infinity();
  bool complete_ = false;
  std::size_t resident_at_start_ = 0;  // peak resident bytes when the run began
  SolveStats stats_;
};

// Progress: the counts as they stand (the Done report: the result's), and a
// fraction that never goes back.
void Solver::report(SolvePhase phase, double fraction, const SolveResult* pass_result) {
  fraction_ = std::max(fraction_, std::clamp(fraction, 0.0, 1.0));
  if (!progress_ || !*progress_) return;
  SolveProgress p;
  p.pass = pass_;
  p.passes = passes_;
  p.phase = phase;
  if (phase == SolvePhase::Done) {
    p.elements = stats_.elements;
    p.leaves = stats_.leaves;
    p.links = stats_.links;
  } else {
    p.elements = hierarchy_.elements().size();
    p.leaves = leaves();
    p.links = links_.size();
  }
  p.threshold = threshold_;
  p.seconds = elapsed();
  p.fraction = fraction_;
  p.pass_result = pass_result;
  (*progress_)(p);
}

// Where `within` (0 to 1) of the current pass lies in the whole solve:
// linking takes the first tenth, each pass an equal share of the rest.
double Solver::pass_fraction(double within) const { return 0.1 + 0.9 * (pass_ + within) / passes_; }

// Elements: the hierarchy (elements, vertices, midpoints) and the per-element
// gather tables; links: the links and their receiver grouping.
void Solver::track_memory() {
  stats_.element_bytes = hierarchy_.memory_bytes() + offset_.capacity() * sizeof(std::uint32_t) +
                         source_.capacity() * sizeof(Rgb) + clusters_.memory_bytes() +
                         cluster_gather_.memory_bytes() +
                         far_light_.capacity() * sizeof(SampleRgb) + balance_.memory_bytes() +
                         direct_light_.capacity() * sizeof(SampleRgb) + dim_sides_.memory_bytes() +
                         ray_light_.capacity() * sizeof(Rgb) + faint_.memory_bytes();
  stats_.link_bytes = links_.capacity() * sizeof(Link) + order_.capacity() * sizeof(std::uint32_t) +
                      cluster_links_.capacity() * sizeof(ClusterLink) +
                      light_links_.capacity() * sizeof(LightLink);
  stats_.peak_bytes = std::max(stats_.peak_bytes, stats_.element_bytes + stats_.link_bytes);
}

// Evaluates links (link_batch.h) until cancelled or out of time, keeping the
// peak of memory they take in the statistics.
std::vector<Link> Solver::evaluate(std::vector<Link>&& candidates) {
  std::vector<Link> made = evaluate_links(
      evaluator_, hierarchy_, std::move(candidates),
      [this] { return cancelled() || out_of_time(); }, stats_.link_cpu, cut_short_);
  stats_.peak_bytes =
      std::max(stats_.peak_bytes, hierarchy_.memory_bytes() + links_.capacity() * sizeof(Link) +
                                      made.capacity() * sizeof(Link));
  return made;
}

// The ray pass (ray_pass.h): the result kept while linking runs, so that a
// solve stopped there (by its budgets or Esc) returns the scene lit, coarsely,
// not black. Nothing here changes what the passes compute: the elements' link
// flags are set for the output mesh only and cleared again.
void Solver::look_by_rays() {
  const auto start = Clock::now();
  RayPass pass =
      ray_pass(hierarchy_, *occluders_.rays, [this] { return cancelled() || out_of_time(); });
  stats_.ray_pass_rays = pass.complete ? pass.rays : 0;
  if (pass.complete) {
    std::vector<SampleRgb> leaf(hierarchy_.elements().size());
    std::vector<Element>& elements = hierarchy_.elements();
    // Shown as the solve will show them: the sides light reaches, without
    // those its stray rays alone reach (RayPass::unlit).
    for (size_t e = 0; e < pass.gathered.size(); ++e) {
      leaf[e].fill(pass.gathered[e]);
      elements[e].has_links = luminance(pass.gathered[e]) > 0.0 && !pass.unlit[e] ? 1 : 0;
    }
    result_.mesh = make_output_mesh(hierarchy_, leaf);
    for (size_t e = 0; e < pass.gathered.size(); ++e) elements[e].has_links = 0;
    count(stats_);
    SolveStats shown = stats_;
    shown.iterations = pass.iterations;
    result_.stats = shown;
  }
  if (pass.complete) {
    // Sides no light reaches (RayPass::unlit) and sides too dim to link
    // (dim_sides.h) take no part in linking; what reaches the dim ones
    // leaves by rays, not links, as what escapes does (energy_balance.h).
    dim_sides_ = DimSides(hierarchy_, pass, options_.dim_share);
    // Measured: with rays at faint samples the gradient oracle made 387
    // elements instead of 843 on a picture 1 mm in front of a wall, 0.4 %
    // darker against Cycles; standard and Noticeable made the same ones.
    if (options_.visibility == VisibilityMode::Exact &&
        !oracle_judges_by_gradients(options_.oracle)) {
      faint_ = FaintSamples(hierarchy_, pass, options_.faint_share);
      evaluator_.faint = &faint_;
    }
    std::vector<float> escaped = std::move(pass.escaped);
    std::vector<std::uint8_t> left_out = std::move(pass.unlit);
    stats_.unlit_sides = static_cast<std::size_t>(std::count(left_out.begin(), left_out.end(), 1));
    stats_.dim_sides = dim_sides_.count();
    for (size_t e = 0; e < dim_sides_.dim().size(); ++e) {
      escaped[e] = std::min(1.0f, escaped[e] + dim_sides_.share_to_dim()[e]);
      left_out[e] |= dim_sides_.dim()[e];
    }
    balance_.set_escaped(std::move(escaped));
    if (stats_.unlit_sides || stats_.dim_sides) clusters_ = ClusterTree(hierarchy_, left_out);
  }
  stats_.seconds_ray_pass = seconds_since(start);
  if (pass.complete) report(SolvePhase::Linking, 0.0, &result_);  // shown while linking runs
}

bool Solver::linking_stopped() const {
  if (cancelled() || out_of_time()) return true;
  if (!memory_hit_ && options_.memory_limit &&
      peak_resident_bytes() > resident_at_start_ + *options_.memory_limit) {
    memory_hit_ = true;
  }
  return memory_hit_;
}

// Links between the top-level patch sides that can exchange light (the
// receiver reflects, the emitter emits or reflects): clusters far apart that
// face each other get one cluster link, pairs facing away are dropped whole,
// before any visibility work; the remaining pairs of sides are evaluated as
// ordinary links (cluster_links.h).
void Solver::link_initially() {
  const auto start = Clock::now();
  // Progress: the walk is the first half of linking, evaluating face links the second.
  // The first pass's links (quality 0): reflecting clusters by distance,
  // emitters by the light a guess of the solution says they carry.
  const ClusterLighting guess =
      estimated_cluster_light(clusters_, hierarchy_, scene_.reference_radiance());
  InitialLinks initial = link_clusters(
      clusters_, hierarchy_, *occluders_.rays,
      cluster_criterion(qualities_.front(), guess, scene_.reference_radiance()),
      [this] { return linking_stopped(); },
      [this](double done) { report(SolvePhase::Linking, 0.05 * done); });
  stats_.seconds_clustering = seconds_since(start);
  // In blocks, so cancellation and progress stay prompt for large scenes.
  const size_t block = 65536;
  std::vector<Link>& candidates = initial.elements;
  for (size_t begin = 0; begin < candidates.size() && !linking_stopped(); begin += block) {
    const size_t end = std::min(candidates.size(), begin + block);
    std::vector<Link> visible =
        evaluate(std::vector<Link>(candidates.begin() + static_cast<std::ptrdiff_t>(begin),
                                   candidates.begin() + static_cast<std::ptrdiff_t>(end)));
    links_.insert(links_.end(), visible.begin(), visible.end());
    report(SolvePhase::Linking,
           0.05 + 0.05 * static_cast<double>(end) / static_cast<double>(candidates.size()));
  }
  candidates = {};
  if (linking_stopped()) {  // the rough look stands (run()); the lights' links would cost as much
                            // again
    stats_.seconds_linking = seconds_since(start);
    return;
  }
  cluster_links_ = std::move(initial.clusters);
  sort_by_receiver(cluster_links_);
  cluster_links_.shrink_to_fit();
  if (!scene_.lights.empty() && !cancelled()) {
    light_links_ = evaluate_light_links(direct_, direct_.initial_links());
    ++light_version_;
  }
  drop_links_light_cannot_reach();
  mark_cluster_receivers_linked();
  if (cluster_links_.empty()) clusters_.release();
  for (const Link& l : links_) hierarchy_.element(l.receiver).has_links = 1;
  for (const LightLink& l : light_links_) hierarchy_.element(l.receiver).has_links = 1;
  for (size_t e = 0; e < dim_sides_.dim().size(); ++e)  // shown, with what their rays gather
    if (dim_sides_.dim()[e]) hierarchy_.element(static_cast<std::int32_t>(e)).has_links = 1;
  links_.shrink_to_fit();
  hierarchy_.shrink_to_fit();
  ++links_version_;
  stats_.seconds_linking = seconds_since(start);
  track_memory();
}

// A link whose form factor is below this at every sample reaches its receiver
// through a crack that rounding opens (the inside of a closed box saw the room
// through its edges at 4e-10 once the scene was scaled to the solver's frame),
// not through a gap in the geometry.
constexpr float kCrack = 1e-9f;

// A side that no light can reach (the inside of a closed box, the floor
// under it) keeps no links: it would never carry any light, yet its links
// would be gathered, its elements shown (doubling the box in the output) and
// its leaks of rounding taken for light. Light starts at the emitting sides
// and the receivers of light links and spreads through the links, from
// emitter to receiver (through links above kCrack); cluster links count as
// reaching every side of their receiving cluster.
void Solver::drop_links_light_cannot_reach() {
  const size_t sides = hierarchy_.root_count();
  std::vector<std::uint8_t> reached(hierarchy_.elements().size(), 0);
  for (size_t r = 0; r < sides; ++r) {
    const std::int32_t root =
        hierarchy_.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (root != kNone && luminance(hierarchy_.emission(hierarchy_.element(root))) > 0.0)
      reached[static_cast<size_t>(root)] = 1;
  }
  for (const LightLink& l : light_links_) reached[static_cast<size_t>(l.receiver)] = 1;
  mark_cluster_receivers(clusters_, hierarchy_, cluster_links_, reached);
  for (bool spread = true; spread;) {
    spread = false;
    for (const Link& l : links_) {
      if (reached[static_cast<size_t>(l.emitter)] && !reached[static_cast<size_t>(l.receiver)] &&
          *std::max_element(l.form_factor.begin(), l.form_factor.end()) > kCrack) {
        reached[static_cast<size_t>(l.receiver)] = 1;
        spread = true;
      }
    }
  }
  std::erase_if(links_, [&](const Link& l) { return !reached[static_cast<size_t>(l.receiver)]; });
}

// Every top-level element under a receiving cluster has links.
void Solver::mark_cluster_receivers_linked() {
  std::vector<std::uint8_t> marked(hierarchy_.root_count(), 0);
  mark_cluster_receivers(clusters_, hierarchy_, cluster_links_, marked);
  for (size_t e = 0; e < marked.size(); ++e)
    if (marked[e]) hierarchy_.element(static_cast<std::int32_t>(e)).has_links = 1;
}

// Cluster links the pass's criterion no longer accepts, with the light the
// clusters send now, are replaced by the walk from them (cluster_links.h):
// finer cluster links, and links between top-level elements, evaluated here.
// Returns whether anything changed.
bool Solver::refine_cluster_links() {
  if (cluster_links_.empty()) return false;
  const ClusterCriterion criterion =
      cluster_criterion(qualities_[static_cast<size_t>(pass_)], cluster_gather_.lighting(),
                        decision_scale_.adaptation);
  if (criterion.lighting->nodes.size() != clusters_.nodes().size()) return false;  // not gathered
  std::vector<ClusterLink> coarse, kept;
  for (const ClusterLink& l : cluster_links_)
    (cluster_link_too_coarse(clusters_, hierarchy_, l, criterion) ? coarse : kept).push_back(l);
  if (coarse.empty()) return false;
  InitialLinks finer = split_cluster_links(clusters_, hierarchy_, *occluders_.rays, criterion,
                                           coarse, [this] { return cancelled() || out_of_time(); });
  if (cancelled() || out_of_time()) {  // a partial walk is discarded with the pass
    refinement_cut_short_ = true;
    return true;
  }
  std::vector<Link> made = evaluate(std::move(finer.elements));
  if (cut_short_) {
    refinement_cut_short_ = true;
    return true;
  }
  for (const Link& l : made) hierarchy_.element(l.receiver).has_links = 1;
  links_.insert(links_.end(), made.begin(), made.end());
  kept.insert(kept.end(), finer.clusters.begin(), finer.clusters.end());
  sort_by_receiver(kept);
  cluster_links_ = std::move(kept);
  mark_cluster_receivers_linked();
  ++links_version_;
  track_memory();
  return true;
}

// Refines every link above the threshold (refine.h), repeatedly, until none
// is, evaluating the new links. Returns whether anything changed.
bool Solver::refine(double threshold) {
  if (!std::isfinite(threshold)) return false;
  decision_scale_ = DecisionScale{options_.oracle, adaptation_radiance(hierarchy_)};
  bool changed = refine_cluster_links();
  if (refinement_cut_short_) return changed;
  while (!cancelled() && !budget_hit_ && !out_of_time()) {
    if (over_memory()) {
      budget_hit_ = memory_hit_ = true;
      break;
    }
    const std::vector<Split> decision =
        choose_splits(hierarchy_, links_, threshold, decision_scale_, limits_);
    SplitLinks round = split_links(hierarchy_, links_, decision, limits_);
    budget_hit_ = budget_hit_ || round.budget_hit;
    hand_down_links(hierarchy_, options_.leaf_links, round);
    const bool lights_changed = refine_light_links(threshold);
    if (round.fresh.empty()) {
      if (lights_changed) {
        changed = true;
        continue;
      }
      break;
    }
    changed = true;
    std::vector<Link> made = evaluate(std::move(round.fresh));
    if (cut_short_) {  // a partial evaluation is discarded with the pass
      refinement_cut_short_ = true;
      break;
    }
    for (const Link& l : made) hierarchy_.element(l.receiver).has_links = 1;
    round.kept.insert(round.kept.end(), made.begin(), made.end());
    links_ = std::move(round.kept);
    ++links_version_;
    track_memory();
    pass_progress_.refined(leaves());
    report(SolvePhase::Refining, pass_fraction(pass_progress_.within()));
  }
  if (changed) {
    // Growth by doubling leaves up to half of each array unused until the next
    // refinement: give it back.
    links_.shrink_to_fit();
    hierarchy_.shrink_to_fit();
    track_memory();
  }
  return changed;
}

// Light links above the threshold split their receivers (refine.h); then every
// light link whose receiver was split (by it or by any link) is replaced by
// its children's. Returns whether the light links changed.
bool Solver::refine_light_links(double threshold) {
  if (light_links_.empty()) return false;
  if (split_light_receivers(hierarchy_, scene_.lights, light_links_, threshold, decision_scale_,
                            limits_))
    budget_hit_ = true;
  std::vector<LightLink> fresh = hand_down_light_links(hierarchy_, light_links_);
  if (fresh.empty()) return false;
  std::vector<LightLink> made = evaluate_light_links(direct_, std::move(fresh));
  for (const LightLink& l : made) hierarchy_.element(l.receiver).has_links = 1;
  light_links_.insert(light_links_.end(), made.begin(), made.end());
  ++light_version_;
  return true;
}

// What each element gathers from the light links, rebuilt when they change.
void Solver::gather_direct_light() {
  if (light_links_.empty() || direct_version_ == light_version_) return;
  direct_light_.assign(hierarchy_.elements().size(), SampleRgb{});
  for (const LightLink& l : light_links_) {
    const Rgb colour = scene_.lights[l.light].colour;
    SampleRgb& out = direct_light_[static_cast<size_t>(l.receiver)];
    for (size_t s = 0; s < kMaxSamples; ++s) out[s] += static_cast<double>(l.value[s]) * colour;
  }
  direct_version_ = light_version_;
}

// Groups the links by receiver (counting sort keeps link order within a
// receiver); rebuilt only when refinement changed the links.
void Solver::group_links() {
  const size_t elements = hierarchy_.elements().size();
  if (links_version_ == grouped_version_ && offset_.size() == elements + 1) return;
  offset_.assign(elements + 1, 0);
  for (const Link& l : links_) ++offset_[static_cast<size_t>(l.receiver) + 1];
  for (size_t i = 1; i < offset_.size(); ++i) offset_[i] += offset_[i - 1];
  order_.resize(links_.size());
  order_.shrink_to_fit();
  std::vector<std::uint32_t> next(offset_.begin(), offset_.end() - 1);
  for (std::uint32_t i = 0; i < links_.size(); ++i)
    order_[next[static_cast<size_t>(links_[i].receiver)]++] = i;
  // Only links whose emitter has been split need its shape.
  tbb::parallel_for(tbb::blocked_range<size_t>(0, links_.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      Link& l = links_[i];
      const Element& emitter = hierarchy_.element(l.emitter);
      if (emitter.is_leaf() || shape_computed(l.emitter_shape)) continue;
      dvec3 receiver[4];
      const int n = hierarchy_.corners(hierarchy_.element(l.receiver), receiver);
      l.emitter_shape = emitter_shape(hierarchy_, emitter,
                                      std::span<const dvec3>(receiver, static_cast<size_t>(n)));
    }
  });
  balance_.update(hierarchy_, LinkGather{hierarchy_, links_, offset_, order_, source_}, clusters_,
                  cluster_links_, cluster_gather_);
  grouped_version_ = links_version_;
}

void Solver::gather_far_light() {
  if (cluster_links_.empty()) {
    // Refinement may replace the last cluster link with element links: what
    // the cluster links gathered before must not be added to theirs.
    far_light_ = {};
    return;
  }
  cluster_gather_(clusters_, cluster_links_, hierarchy_, source_, far_light_);
}

// One Jacobi iteration: the links read the radiances as they are now.
double Solver::gather_push_pull() {
  group_links();
  balance_.sent_radiances(hierarchy_, source_);
  gather_far_light();
  gather_direct_light();
  if (!dim_sides_.empty()) dim_sides_.gather(hierarchy_, ray_light_);
  return push_pull(hierarchy_, LinkGather{hierarchy_, links_, offset_, order_, source_}, far_light_,
                   balance_.down_scale(), direct_light_, ray_light_);
}

// Refine, gather, push/pull until converged (or `max_iterations`); refinement
// waits until the radiances have moved by 1e-3 since `drift` was measured.
// Returns the last residual.
double Solver::iterate(double threshold, int max_iterations, double tolerance, double drift) {
  double residual = 0.0;
  // `drift`: radiance change since refinement last found nothing to do:
  // decisions can only change once the radiances they read have moved (a
  // converging high-albedo scene iterates hundreds of times without new
  // refinement).
  TailExtrapolation tail;
  for (int i = 0; i < max_iterations && !pass_abandoned(); ++i) {
    bool refined = false;
    if (drift > 1e-3) {
      refined = refine(threshold);
      drift = refined ? std::numeric_limits<double>::infinity() : 0.0;
    }
    if (pass_abandoned()) break;
    const auto start = Clock::now();
    tail.before(hierarchy_);
    residual = gather_push_pull();
    const bool extrapolated = tail.after(hierarchy_, residual, refined);
    stats_.seconds_gather += seconds_since(start);
    ++stats_.iterations;
    stats_.residual = residual;
    pass_progress_.gathered(residual, tolerance, i + 1, max_iterations);
    report(SolvePhase::Gathering, pass_fraction(pass_progress_.within()));
    if (std::isfinite(drift)) drift += residual;
    if (extrapolated) continue;  // not converged until an iteration confirms it
    // A pass cut short by the element budget is the last: converge it fully.
    if (!refined && residual < (budget_hit_ ? options_.tolerance : tolerance)) break;
    // The budget ends the pass once an iteration has gathered (from the last refinement, if any).
    if (out_of_time()) break;
  }
  return residual;
}

void Solver::snapshot(double threshold) {
  // The same radiances as the last iteration read: this push/pull repeats it,
  // keeping what each leaf sample gathered. Before the first iteration nothing
  // has been gathered yet (emitters only): the links read zero.
  std::vector<std::array<Rgb, kMaxSamples>> leaf(hierarchy_.elements().size());
  source_.reserve(hierarchy_.elements().size());  // exactly: no half-empty growth
  source_.resize(hierarchy_.elements().size(), Rgb(0.0));
  group_links();
  gather_far_light();
  gather_direct_light();  // ray_light_: as the last iteration gathered it
  push_pull(hierarchy_, LinkGather{hierarchy_, links_, offset_, order_, source_}, far_light_,
            balance_.down_scale(), direct_light_, ray_light_, &leaf);
  result_.mesh = make_output_mesh(hierarchy_, leaf);
  stats_.threshold = threshold;
  count(stats_);
}

// Pass 0 solves without refinement (quality 0: the coarsest links), later
// passes raise the quality, and so lower the thresholds geometrically, to the
// target. Fixed bounces: one pass.
std::vector<double> Solver::pass_qualities() const {
  if (options_.bounces) return {options_.quality};
  std::vector<double> qualities = {0.0};
  if (options_.quality > 0.0) {
    const int steps = std::max(1, static_cast<int>(std::ceil(6 * options_.quality)));
    for (int k = 1; k <= steps; ++k) qualities.push_back(options_.quality * k / steps);
  }
  return qualities;
}

// What a cluster link must satisfy at `quality` (cluster_links.h), with the
// light each cluster sends and the adaptation radiance as they stand.
ClusterCriterion Solver::cluster_criterion(double quality, const ClusterLighting& lighting,
                                           double adaptation) const {
  ClusterCriterion c;
  c.separation = cluster_separation(options_, quality);
  // An infinite separation asks for pairs of sides only.
  c.threshold = std::isinf(c.separation) ? std::numeric_limits<double>::infinity()
                                         : cluster_threshold(quality);
  c.adaptation = adaptation;
  c.total_area = scene_.total_area;
  c.lighting = &lighting;
  c.rays = kClusterRays;
  return c;
}

// The counts of the solution as it stands.
void Solver::count(SolveStats& stats) const {
  const auto& elements = hierarchy_.elements();
  stats.elements = elements.size();
  stats.leaves = static_cast<size_t>(std::count_if(elements.begin(), elements.end(),
                                                   [](const Element& e) { return e.is_leaf(); }));
  stats.links = links_.size();
  stats.cluster_links = cluster_links_.size();
  stats.light_links = light_links_.size();
}

// What every call starts from: its options' limits, callbacks and clock, and
// statistics of its own (the counts stay those of the solution).
void Solver::begin(const SolveOptions& options, const ProgressCallback& progress,
                   const CancelCheck& cancel) {
  options_ = options;
  progress_ = &progress;
  cancel_ = &cancel;
  stopped_ = false;
  start_ = Clock::now();
  clock_start_ = options.clock ? options.clock() : 0.0;
  limits_ = {options.min_element_area * scene_.total_area, options.max_elements};
  memory_limit_ = options.memory_limit.value_or(std::numeric_limits<std::size_t>::max());
  budget_hit_ = memory_hit_ = cut_short_ = refinement_cut_short_ = complete_ = false;
  fraction_ = 0.0;
  const SolveStats counts = stats_;
  stats_ = SolveStats{};
  stats_.element_bytes = counts.element_bytes;
  stats_.link_bytes = counts.link_bytes;
  stats_.stopped_by = StopReason::Quality;
}

SolveResult Solver::run(const ProgressCallback& progress, const CancelCheck& cancel) {
  begin(options_, progress, cancel);
  resident_at_start_ = peak_resident_bytes();
  qualities_ = pass_qualities();
  passes_ = static_cast<int>(qualities_.size());
  report(SolvePhase::Linking, 0.0);
  look_by_rays();
  link_initially();
  if (linking_stopped()) {
    if (memory_hit_)
      stats_.stopped_by = StopReason::Memory;
    else if (out_of_time() || cut_short_)
      stats_.stopped_by = StopReason::TimeBudget;
    return end();  // with the ray pass's light, if it finished
  }
  snapshot(std::numeric_limits<double>::infinity());  // emitters only
  solve_passes(kUnknownDrift);
  return end();
}

SolveResult Solver::relight(const SolveOptions& options, double scale,
                            const ProgressCallback& progress, const CancelCheck& cancel) {
  begin(options, progress, cancel);
  stats_.reused = true;
  // One pass at the target threshold: the kept solution already passed the
  // coarser ones, with the old radiances as the start.
  qualities_ = {pass_qualities().back()};
  passes_ = 1;
  report(SolvePhase::Linking, 0.0);
  // Which sides reflect and what the lights give changed: regroup (the energy
  // balance depends on who reflects) and gather the light links anew.
  ++links_version_;
  ++light_version_;
  // Converge on the kept elements first: refinement decided on radiances half
  // way from the old lighting to the new would split what neither needs. Then
  // refine only if the radiances moved relative to the adaptation level, which
  // is what the oracles read: a light made brighter changes no decision. The
  // start is the old solution scaled like the lighting (exact when every light
  // changed alike); a change clear at 1e-3 needs no further convergence first.
  const std::vector<double> before = relative_luminance(hierarchy_);
  for (std::int32_t e = 0; e < static_cast<std::int32_t>(hierarchy_.elements().size()); ++e)
    hierarchy_.element(e).radiance *= scale;
  constexpr double kClearChange = 1e-2;
  iterate(kNoRefinement, options_.max_iterations, 1e-3);
  double drift = relative_luminance_change(hierarchy_, before);
  if (drift < kClearChange) {
    iterate(kNoRefinement, options_.max_iterations, options_.tolerance);
    drift = relative_luminance_change(hierarchy_, before);
  }
  solve_passes(drift);
  return end();
}

// The passes of decreasing threshold, each iterated to convergence, until the
// last, a budget or cancel. `drift`: how far the radiances moved since the
// hierarchy was last refined for them (iterate).
void Solver::solve_passes(double drift) {
  for (pass_ = 0; pass_ < passes_; ++pass_) {
    if (cancelled()) break;
    threshold_ = quality_threshold(options_.oracle, qualities_[static_cast<size_t>(pass_)]);
    pass_progress_.start(leaves());
    const bool last = pass_ + 1 == passes_;
    if (options_.bounces) {
      iterate(threshold_, *options_.bounces, -1.0, drift);
    } else {
      iterate(threshold_, options_.max_iterations, last ? options_.tolerance : 1e-3, drift);
    }
    drift = kUnknownDrift;  // a new threshold: every link is judged again
    if (pass_abandoned()) break;
    snapshot(threshold_);
    stats_.passes = pass_ + 1;
    stats_.seconds = elapsed();
    result_.stats = stats_;
    report(SolvePhase::Pass, pass_fraction(1.0), &result_);
    if (budget_hit_) {
      stats_.stopped_by = memory_hit_ ? StopReason::Memory : StopReason::MaxElements;
      break;
    }
    if (out_of_time()) {
      stats_.stopped_by = StopReason::TimeBudget;
      break;
    }
  }
}

SolveResult Solver::end() {
  if (refinement_cut_short_) stats_.stopped_by = StopReason::TimeBudget;
  if (cancelled()) {
    stats_.cancelled = true;
    stats_.stopped_by = StopReason::Cancel;
  }
  // The hierarchy and links stand only if no evaluation of links was cut short
  // (linking, or a pass abandoned half-refined) and a pass gathered over them.
  complete_ = !cancelled() && !cut_short_ && !refinement_cut_short_ && stats_.passes > 0;
  // The counts stay those of the last snapshot: the solution returned.
  stats_.skipped_faces = scene_.skipped.size();
  stats_.repaired_faces = noted_faces(scene_.repaired);
  track_memory();
  stats_.seconds = elapsed();
  result_.stats = stats_;
  report(SolvePhase::Done, 1.0);
  progress_ = nullptr;  // the call's, gone after it
  cancel_ = nullptr;
  SolveResult out = std::move(result_);
  result_ = SolveResult{};
  return out;
}

}  // namespace

std::size_t estimated_base_bytes(const Scene& scene) {
  // Per patch: two sides' elements with their gather state, the cluster tree
  // (about two nodes per side), and Embree's BVH (about 128 bytes a primitive).
  constexpr std::size_t kPerSide = sizeof(Element) + 2 * sizeof(ClusterNode) + 4 * sizeof(Rgb);
  constexpr std::size_t kPerPatch = sizeof(Patch) + 2 * kPerSide + 128;
  return scene.patches.size() * kPerPatch;
}

double quality_threshold(Oracle oracle, double quality) {
  if (!(quality > 0.0)) return std::numeric_limits<double>::infinity();
  return log_interpolate(threshold_range(oracle), quality);
}

// A complete solve and the scene it was made for (the solver refers to it),
// whose lighting each relight replaces.
struct SolveReuse::Kept {
  Scene scene;
  std::unique_ptr<Solver> solver;
};

SolveReuse::SolveReuse() = default;
SolveReuse::~SolveReuse() = default;

void SolveReuse::clear() { kept_.reset(); }

std::size_t SolveReuse::memory_bytes() const {
  return kept_ ? kept_->solver->memory_bytes() +
                     (kept_->scene.patches.size() + kept_->scene.occluders.size()) * sizeof(Patch)
               : 0;
}

RelightRefusal SolveReuse::refusal(const Scene& scene, const SolveOptions& options) const {
  if (!kept_) return RelightRefusal::NothingKept;
  return relight_refusal(kept_->scene, kept_->solver->options(), scene, options);
}

SolveResult solve(const Scene& scene, const SolveOptions& options, const ProgressCallback& progress,
                  const CancelCheck& cancel, SolveReuse* reuse) {
  if (!(options.quality >= 0.0 && options.quality <= 1.0)) {
    throw std::invalid_argument("quality must lie in [0, 1]");
  }
  if (options.max_elements && *options.max_elements == 0) {
    throw std::invalid_argument("max_elements must be positive");
  }
  if (options.time_budget && !(*options.time_budget > 0.0)) {
    throw std::invalid_argument("time_budget must be positive seconds");
  }
  if (options.rays < 1 || options.rays > kMaxRays)
    throw std::invalid_argument("rays must lie in [1, " + std::to_string(kMaxRays) + "]");
  if (options.bounces && *options.bounces < 1)
    throw std::invalid_argument("bounces must be at least 1");
  if (options.threads && (*options.threads < 1 || *options.threads > kMaxThreads))
    throw std::invalid_argument("threads must lie in [1, " + std::to_string(kMaxThreads) + "]");
  if (!(options.min_element_area > 0.0 && options.min_element_area < 1.0)) {
    throw std::invalid_argument("min_element_area must lie in (0, 1)");
  }
  SolveOptions checked = options;
  if (!checked.memory_limit) checked.memory_limit = available_memory() / 4 * 3;
  const std::size_t needed = estimated_base_bytes(scene);
  if (needed > *checked.memory_limit) {
    std::ostringstream m;
    m << "the scene needs about " << gigabytes(needed)
      << " GB before any refinement, more than the " << gigabytes(*checked.memory_limit)
      << " GB the solve may use (" << scene.patches.size()
      << " planar pieces); solve fewer or simpler objects";
    throw InsufficientMemory(m.str());
  }
  tbb::task_arena arena(options.threads ? *options.threads : tbb::task_arena::automatic);
  std::optional<YieldPriority> yielding;
  if (options.yield_to_interface) {
    arena.initialize();  // an observer needs its arena
    yielding.emplace(arena);
    lower_this_thread_priority();  // the calling thread works in the arena too
  }
  auto run = [&] {
    if (!reuse) return Solver(scene, checked).run(progress, cancel);
    const RelightRefusal refusal = reuse->refusal(scene, checked);
    if (refusal == RelightRefusal::None) {
      SolveReuse::Kept& kept = *reuse->kept_;
      const double scale = lighting_scale(kept.scene, scene);
      take_lighting(kept.scene, scene);
      SolveResult relit = kept.solver->relight(checked, scale, progress, cancel);
      if (!kept.solver->complete()) reuse->clear();
      return relit;
    }
    reuse->clear();  // its memory is the new solve's
    auto kept = std::make_unique<SolveReuse::Kept>();
    kept->scene = scene;
    kept->solver = std::make_unique<Solver>(kept->scene, checked);
    SolveResult solved = kept->solver->run(progress, cancel);
    solved.stats.reuse_refusal = refusal;
    if (kept->solver->complete()) reuse->kept_ = std::move(kept);
    return solved;
  };
  try {
    SolveResult result = arena.execute(run);
    require_finite(result.mesh);
    return result;
  } catch (...) {
    if (reuse) reuse->clear();  // a relight that failed half way leaves nothing to trust
    throw;
  }
}

}  // namespace radiosity
