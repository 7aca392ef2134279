#include "core/solver.h"

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "core/cluster_links.h"
#include "core/cluster_tree.h"
#include "core/convergence.h"
#include "core/direct_light.h"
#include "core/energy_balance.h"
#include "core/gather.h"
#include "core/timing.h"

namespace radiosity {
namespace {

// Threshold range of each oracle over quality (0, 1], log-spaced. Measured on
// a 4 x 4 x 3 m room with a ceiling light and a box (tests/native), so that the
// three oracles make similar element counts at the same quality (about 4,000 at
// 0.5) and 0.1 barely refines; see bench/ for the sweeps.
struct ThresholdRange {
  double coarse, fine;
};

ThresholdRange threshold_range(Oracle oracle) {
  switch (oracle) {
    case Oracle::Standard:
      return {1e-2, 1e-7};
    case Oracle::Perceptual:
      return {1.0, 4e-3};
    case Oracle::Gradient:
      return {1e-1, 2.5e-4};
  }
  return {1.0, 1e-4};
}

enum class Split : std::uint8_t { None, Receiver, Emitter };

// Emitted power over area divided by the mean radiance of the lit sides, in
// the calibration room (threshold_range), measured: keeps its refinement.
constexpr double kAdaptationCalibration = 0.52;

// Far enough apart for a cluster link: the emitter cluster's light is taken
// as if it left from its centroid, which errs more the larger it looks from
// the receiver, so finer quality asks for more distance.
double cluster_separation(const SolveOptions& options) {
  return options.cluster_separation > 0.0 ? options.cluster_separation
                                          : 2.0 + 8.0 * options.quality;
}

// Light a light link's samples miss (LightLink::missed) is refined for when it
// would reach this fraction of the radiance the eye adapts to.
constexpr double kMissedLight = 0.01;

// Shadow rays that measure a cluster link's visible fraction.
constexpr int kClusterRays = 16;

// Bytes of memory available now (Linux: MemAvailable), or a large number
// where it cannot be read.
std::size_t available_memory() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  std::size_t kilobytes = 0;
  std::string unit;
  while (meminfo >> key >> kilobytes >> unit) {
    if (key == "MemAvailable:") return kilobytes * 1024;
  }
  const long pages = sysconf(_SC_AVPHYS_PAGES), page = sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0)
    return static_cast<std::size_t>(pages) * static_cast<std::size_t>(page);
  return std::numeric_limits<std::size_t>::max() / 2;
}

double gigabytes(std::size_t bytes) { return std::round(static_cast<double>(bytes) / 1e8) / 10.0; }

class Solver {
 public:
  Solver(const Scene& scene, const SolveOptions& options, const ProgressCallback& progress,
         const CancelCheck& cancel)
      : scene_(scene),
        options_(options),
        progress_(progress),
        cancel_(cancel),
        start_(Clock::now()),
        hierarchy_(scene),
        occluders_(make_scene_occluders(scene)),
        evaluator_{hierarchy_,         occluders_,
                   options.visibility, options.rays,
                   options.oracle,     oracle_geometric_scale(options.oracle, scene.total_area)},
        direct_(hierarchy_, occluders_, options.visibility, options.rays, options.oracle,
                oracle_geometric_scale(options.oracle, scene.total_area)),
        min_area_(options.min_element_area * scene.total_area),
        memory_limit_(options.memory_limit.value_or(std::numeric_limits<std::size_t>::max())),
        clusters_(hierarchy_) {}

  SolveResult run();

 private:
  bool cancelled() const {
    if (!stopped_ && cancel_ && cancel_()) stopped_ = true;
    return stopped_;
  }
  double elapsed() const { return seconds_since(start_); }
  bool out_of_time() const { return options_.time_budget && elapsed() > *options_.time_budget; }
  // Cancelled, or a refinement cut short by the time budget: the pass is
  // abandoned and the last complete one stands.
  bool pass_abandoned() const { return cancelled() || refinement_cut_short_; }

  void report(const std::string& phase, double fraction);
  void link_initially();
  void drop_links_light_cannot_reach();
  std::vector<Link> evaluate_links(std::vector<Link>&& candidates);
  std::vector<LightLink> evaluate_light_links(std::vector<LightLink>&& candidates);
  bool refine(double threshold);
  bool refine_light_links(double threshold);
  void gather_direct_light();
  double adaptation_radiance() const;
  Split choose_split(const Link& link, double threshold) const;
  bool over_memory() const { return stats_.element_bytes + stats_.link_bytes > memory_limit_; }
  bool can_split(std::int32_t e) const { return hierarchy_.element(e).area / 4.0 >= min_area_; }
  bool near_field(const Link& link, bool receiver_end) const;
  void group_links();
  void gather_far_light();
  double gather_push_pull();
  double iterate(double threshold, int max_iterations, double tolerance);
  void snapshot(double threshold);
  void track_memory();

  const Scene& scene_;
  const SolveOptions options_;
  const ProgressCallback& progress_;
  const CancelCheck& cancel_;
  mutable std::atomic<bool> stopped_{false};  // read and set from worker threads
  const Clock::time_point start_;
  Hierarchy hierarchy_;
  SceneOccluders occluders_;
  LinkEvaluator evaluator_;
  DirectLight direct_;
  // Brightness the oracles' thresholds are relative to (refine()).
  double reference_radiance_ = 0.0;
  const double min_area_;
  const std::size_t memory_limit_;  // bytes of elements and links (SolveOptions::memory_limit)
  std::vector<Link> links_;
  // Links grouped by receiver for the gather, and which links they describe.
  std::vector<std::uint32_t> offset_, order_;
  std::vector<Rgb> source_;  // radiance per element as the last gather read it (what each sends)
  EnergyBalance balance_;    // corrections of what is received and sent (energy_balance.h)
  ClusterTree clusters_;
  std::vector<ClusterLink> cluster_links_;
  ClusterGather cluster_gather_;
  std::vector<Rgb> far_light_;  // what each top-level element gathers through cluster links
  // Light from the lights that are not surfaces: one link per leaf and light
  // that reaches it, and what each element gathers from them at its samples.
  std::vector<LightLink> light_links_;
  std::vector<SampleRgb> direct_light_;
  std::uint64_t light_version_ = 1, direct_version_ = 0;
  std::uint64_t links_version_ = 1, grouped_version_ = 0;
  SolveResult result_;       // the last complete pass
  bool budget_hit_ = false;  // max_elements or memory_limit reached
  bool memory_hit_ = false;
  bool cut_short_ = false;             // the last evaluate_links stopped before the end
  bool refinement_cut_short_ = false;  // ... within refine(): the pass is abandoned
  int pass_ = 0, passes_ = 1;
  double threshold_ = std::numeric_limits<double>::infinity();
  SolveStats stats_;
};

void Solver::report(const std::string& phase, double fraction) {
  if (!progress_) return;
  SolveProgress p;
  p.pass = pass_;
  p.passes = passes_;
  p.phase = phase;
  p.elements = hierarchy_.elements().size();
  p.links = links_.size();
  p.threshold = threshold_;
  p.seconds = elapsed();
  p.fraction = std::clamp(fraction, 0.0, 1.0);
  progress_(p);
}

// Elements: the hierarchy (elements, vertices, midpoints) and the per-element
// gather tables; links: the links and their receiver grouping.
void Solver::track_memory() {
  stats_.element_bytes = hierarchy_.memory_bytes() + offset_.capacity() * sizeof(std::uint32_t) +
                         source_.capacity() * sizeof(Rgb) + clusters_.memory_bytes() +
                         cluster_gather_.memory_bytes() + far_light_.capacity() * sizeof(Rgb) +
                         balance_.memory_bytes() + direct_light_.capacity() * sizeof(SampleRgb);
  stats_.link_bytes = links_.capacity() * sizeof(Link) + order_.capacity() * sizeof(std::uint32_t) +
                      cluster_links_.capacity() * sizeof(ClusterLink) +
                      light_links_.capacity() * sizeof(LightLink);
  stats_.peak_bytes = std::max(stats_.peak_bytes, stats_.element_bytes + stats_.link_bytes);
}

// Evaluates links in parallel, each into its own slot, and keeps the visible
// ones in their original order: the result does not depend on the thread count.
// Runs of up to four links made by one split (refine keeps them consecutive)
// are evaluated together: sibling receivers linked to one emitter share their
// common corners (CornerMemo); one receiver linked to sibling emitters shares
// the parent emitter's shaft and visible region. The runs depend only on the
// link order.
std::vector<Link> Solver::evaluate_links(std::vector<Link>&& candidates) {
  enum class Run : std::uint8_t { Single, SiblingReceivers, SiblingEmitters };
  const auto parent = [&](std::int32_t e) { return hierarchy_.element(e).parent; };
  const auto run_of = [&](const Link& a, const Link& b) {
    // Roots have no parent: they never come from one split.
    if (a.emitter == b.emitter && parent(a.receiver) != kNone &&
        parent(a.receiver) == parent(b.receiver))
      return Run::SiblingReceivers;
    if (a.receiver == b.receiver && parent(a.emitter) != kNone &&
        parent(a.emitter) == parent(b.emitter))
      return Run::SiblingEmitters;
    return Run::Single;
  };
  std::vector<std::uint32_t> group_start;
  std::vector<Run> group_kind;
  for (size_t i = 0; i < candidates.size(); ++i) {
    const Run run = i > 0 ? run_of(candidates[i - 1], candidates[i]) : Run::Single;
    const bool continues = !group_start.empty() && i - group_start.back() < 4 &&
                           run != Run::Single &&
                           (group_kind.back() == Run::Single || group_kind.back() == run);
    if (continues) {
      group_kind.back() = run;
    } else {
      group_start.push_back(static_cast<std::uint32_t>(i));
      group_kind.push_back(Run::Single);
    }
  }
  group_start.push_back(static_cast<std::uint32_t>(candidates.size()));
  const size_t groups = group_kind.size();

  std::vector<std::uint8_t> visible(candidates.size(), 0);
  tbb::enumerable_thread_specific<LinkTimings> timings;
  // Chunks keep cancellation prompt without a check per link.
  const size_t chunk = 1024;
  for (size_t begin = 0; begin < groups && !cancelled() && !out_of_time(); begin += chunk) {
    const size_t end = std::min(groups, begin + chunk);
    tbb::parallel_for(tbb::blocked_range<size_t>(begin, end), [&](const auto& range) {
      LinkTimings& local = timings.local();
      for (size_t g = range.begin(); g != range.end(); ++g) {
        const size_t first = group_start[g], count = group_start[g + 1] - first;
        if (group_kind[g] == Run::SiblingEmitters) {
          evaluator_.evaluate_emitter_siblings(
              std::span<Link>(candidates.data() + first, count), local,
              std::span<std::uint8_t>(visible.data() + first, count));
          continue;
        }
        CornerMemo memo;
        for (size_t i = first; i < first + count; ++i) {
          visible[i] = evaluator_.evaluate(candidates[i], local, &memo) ? 1 : 0;
        }
      }
    });
  }
  for (const LinkTimings& t : timings) stats_.link_cpu += t;
  cut_short_ = groups > 0 && (cancelled() || out_of_time());
  size_t kept = 0;
  for (size_t i = 0; i < candidates.size(); ++i) {
    if (visible[i]) candidates[kept++] = candidates[i];
  }
  candidates.resize(kept);
  stats_.peak_bytes =
      std::max(stats_.peak_bytes, hierarchy_.memory_bytes() + links_.capacity() * sizeof(Link) +
                                      candidates.capacity() * sizeof(Link));
  return std::move(candidates);
}

// Evaluates light links in parallel and keeps those that deliver light, in
// their original order (deterministic for any thread count).
std::vector<LightLink> Solver::evaluate_light_links(std::vector<LightLink>&& candidates) {
  std::vector<std::uint8_t> lit(candidates.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, candidates.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i)
      lit[i] = direct_.evaluate(candidates[i]) ? 1 : 0;
  });
  size_t kept = 0;
  for (size_t i = 0; i < candidates.size(); ++i)
    if (lit[i]) candidates[kept++] = candidates[i];
  candidates.resize(kept);
  return std::move(candidates);
}

// Links between the top-level patch sides that can exchange light (the
// receiver reflects, the emitter emits or reflects): clusters far apart that
// face each other get one cluster link, pairs facing away are dropped whole,
// before any visibility work; the remaining pairs of sides are evaluated as
// ordinary links (cluster_links.h).
void Solver::link_initially() {
  const auto start = Clock::now();
  // Progress: the walk is the first half of linking, evaluating face links the second.
  InitialLinks initial = link_clusters(
      clusters_, hierarchy_, *occluders_.rays, cluster_separation(options_), kClusterRays,
      [this] { return cancelled() || out_of_time(); },
      [this](double done) { report("linking", 0.05 * done); });
  stats_.seconds_clustering = seconds_since(start);
  // In blocks, so cancellation and progress stay prompt for large scenes.
  const size_t block = 65536;
  std::vector<Link>& candidates = initial.elements;
  for (size_t begin = 0; begin < candidates.size() && !cancelled() && !out_of_time();
       begin += block) {
    const size_t end = std::min(candidates.size(), begin + block);
    std::vector<Link> visible =
        evaluate_links(std::vector<Link>(candidates.begin() + static_cast<std::ptrdiff_t>(begin),
                                         candidates.begin() + static_cast<std::ptrdiff_t>(end)));
    links_.insert(links_.end(), visible.begin(), visible.end());
    report("linking",
           0.05 + 0.05 * static_cast<double>(end) / static_cast<double>(candidates.size()));
  }
  candidates = {};
  cluster_links_ = std::move(initial.clusters);
  cluster_links_.shrink_to_fit();
  if (!scene_.lights.empty() && !cancelled()) {
    light_links_ = evaluate_light_links(direct_.initial_links());
    ++light_version_;
  }
  drop_links_light_cannot_reach();
  for (const ClusterLink& l : cluster_links_) {
    const ClusterNode& node = clusters_.node(l.receiver);
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
      hierarchy_.element(clusters_.sides()[i]).has_links = 1;
  }
  if (cluster_links_.empty()) clusters_.release();
  for (const Link& l : links_) hierarchy_.element(l.receiver).has_links = 1;
  for (const LightLink& l : light_links_) hierarchy_.element(l.receiver).has_links = 1;
  links_.shrink_to_fit();
  hierarchy_.shrink_to_fit();
  ++links_version_;
  stats_.seconds_linking = seconds_since(start);
  track_memory();
}

// A side that no light can reach (the inside of a closed box, the floor
// under it) keeps no links: it would never carry any light, yet its links
// would be gathered, its elements shown (doubling the box in the output) and
// its leaks of rounding taken for light. Light starts at the emitting sides
// and the receivers of light links and spreads through the links, from
// emitter to receiver; cluster links count as reaching every side of their
// receiving cluster.
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
  for (const ClusterLink& l : cluster_links_) {
    const ClusterNode& node = clusters_.node(l.receiver);
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
      reached[static_cast<size_t>(clusters_.sides()[i])] = 1;
  }
  for (bool spread = true; spread;) {
    spread = false;
    for (const Link& l : links_) {
      if (reached[static_cast<size_t>(l.emitter)] && !reached[static_cast<size_t>(l.receiver)]) {
        reached[static_cast<size_t>(l.receiver)] = 1;
        spread = true;
      }
    }
  }
  std::erase_if(links_, [&](const Link& l) { return !reached[static_cast<size_t>(l.receiver)]; });
}

// Is one end of the link closer to the other than twice its own radius? Then
// the form factor varies over that end in ways five samples (receiver) or a
// split in four (emitter shape) cannot follow: it grows quickly towards a
// shared edge. Such links follow a split end down instead.
bool Solver::near_field(const Link& link, bool receiver_end) const {
  const Element& p = hierarchy_.element(link.receiver);
  const Element& q = hierarchy_.element(link.emitter);
  const double rp = 0.5 * hierarchy_.diameter(p), rq = 0.5 * hierarchy_.diameter(q);
  const double gap = glm::length(hierarchy_.centre(p) - hierarchy_.centre(q)) - rp - rq;
  return gap < 2.0 * (receiver_end ? rp : rq);
}

// The mean radiance of the lit and emitting sides, as the solution stands:
// the brightness an eye adapts to, which thresholds are relative to. With
// the emitted power over the area instead, a white room (whose mean radiance
// is 1 / (1 - rho) times larger) refined as if seen ten to a hundred times
// brighter: 5.5 million links at rho = 0.9. Scaled by kAdaptationCalibration
// so that the test room the thresholds were calibrated on (see
// threshold_range) refines as before.
double Solver::adaptation_radiance() const {
  double light = 0.0, area = 0.0;
  for (size_t r = 0; r < hierarchy_.root_count(); ++r) {
    const std::int32_t root =
        hierarchy_.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (root == kNone) continue;
    const Element& e = hierarchy_.element(root);
    if (!e.has_links && !(luminance(hierarchy_.emission(e)) > 0.0)) continue;
    light += e.area * luminance(e.radiance);
    area += e.area;
  }
  const double mean = area > 0.0 ? light / area : 0.0;
  return mean > 0.0 ? kAdaptationCalibration * mean : scene_.reference_radiance();
}

// The refinement policy shared by every oracle (DESIGN s5): split the larger
// of receiver and emitter unless it is at the minimum size, then the other.
Split Solver::choose_split(const Link& link, double threshold) const {
  const Element& p = hierarchy_.element(link.receiver);
  const Element& q = hierarchy_.element(link.emitter);
  const double brightness = luminance(hierarchy_.reflectance(p) * q.radiance);
  if (!(brightness / reference_radiance_ * link.oracle > threshold)) return Split::None;
  const bool receiver_first = p.area >= q.area;
  const std::int32_t first = receiver_first ? link.receiver : link.emitter;
  const std::int32_t second = receiver_first ? link.emitter : link.receiver;
  if (can_split(first)) return receiver_first ? Split::Receiver : Split::Emitter;
  if (can_split(second)) return receiver_first ? Split::Emitter : Split::Receiver;
  return Split::None;
}

// Refines every link above the threshold, repeatedly, until none is. Returns
// whether anything changed.
bool Solver::refine(double threshold) {
  if (!std::isfinite(threshold)) return false;
  reference_radiance_ = adaptation_radiance();
  bool changed = false;
  while (!cancelled() && !budget_hit_ && !out_of_time()) {
    if (over_memory()) {
      budget_hit_ = memory_hit_ = true;
      break;
    }
    std::vector<Split> decision(links_.size(), Split::None);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, links_.size()), [&](const auto& range) {
      for (size_t i = range.begin(); i != range.end(); ++i)
        decision[i] = choose_split(links_[i], threshold);
    });
    // Subdivide in link order (deterministic), within the element budget.
    std::vector<Link> kept, fresh;
    for (size_t i = 0; i < links_.size(); ++i) {
      const Link& link = links_[i];
      if (decision[i] != Split::None) {
        const std::int32_t target = decision[i] == Split::Receiver ? link.receiver : link.emitter;
        const bool split_already = !hierarchy_.element(target).is_leaf();
        if (!split_already && options_.max_elements &&
            hierarchy_.elements().size() + 4 > *options_.max_elements) {
          budget_hit_ = true;
          decision[i] = Split::None;
        } else {
          const std::int32_t child = hierarchy_.subdivide(target);
          for (std::int32_t c = child; c < child + 4; ++c) {
            Link l;
            l.receiver = decision[i] == Split::Receiver ? c : link.receiver;
            l.emitter = decision[i] == Split::Emitter ? c : link.emitter;
            fresh.push_back(l);
          }
          continue;
        }
      }
      kept.push_back(link);
    }
    if (options_.leaf_links != SolveOptions::LeafLinks::None) {
      // A split receiver hands its links down, so its samples' values are
      // gathered, not interpolated from a coarser element: near-field links
      // ("near"), or all of them ("all"), which also hands near-field links
      // from a split emitter down to its children, so that they send what
      // each part of the emitter reflects. Fresh links too: their ends may
      // have been split by another link.
      const bool all = options_.leaf_links == SolveOptions::LeafLinks::All;
      const auto hand_down = [&](std::vector<Link>& links, std::vector<Link>& staying,
                                 std::vector<Link>& moved) {
        for (const Link& link : links) {
          const Element& receiver = hierarchy_.element(link.receiver);
          const Element& emitter = hierarchy_.element(link.emitter);
          const bool receiver_down = !receiver.is_leaf() && (all || near_field(link, true));
          const bool emitter_down =
              !receiver_down && all && !emitter.is_leaf() && near_field(link, false);
          if (!receiver_down && !emitter_down) {
            staying.push_back(link);
            continue;
          }
          const std::int32_t first = receiver_down ? receiver.first_child : emitter.first_child;
          for (std::int32_t c = first; c < first + 4; ++c) {
            Link l;
            l.receiver = receiver_down ? c : link.receiver;
            l.emitter = receiver_down ? link.emitter : c;
            moved.push_back(l);
          }
        }
      };
      std::vector<Link> staying, fresh_leaves;
      hand_down(kept, staying, fresh);
      hand_down(fresh, fresh_leaves, fresh_leaves);
      kept = std::move(staying);
      fresh = std::move(fresh_leaves);
    }
    const bool lights_changed = refine_light_links(threshold);
    if (fresh.empty()) {
      if (lights_changed) {
        changed = true;
        continue;
      }
      break;
    }
    changed = true;
    std::vector<Link> made = evaluate_links(std::move(fresh));
    if (cut_short_) {  // a partial evaluation is discarded with the pass
      refinement_cut_short_ = true;
      break;
    }
    for (const Link& l : made) hierarchy_.element(l.receiver).has_links = 1;
    kept.insert(kept.end(), made.begin(), made.end());
    links_ = std::move(kept);
    ++links_version_;
    track_memory();
    report("refining", (pass_ + 0.5) / (passes_ + 1.0));
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

// Light links take part in refinement like links whose emitter cannot be
// split: one above the threshold splits its receiver. Then every light link
// whose receiver was split (by it or by any link) is replaced by its
// children's, so direct light is always evaluated at the leaves that gather
// it. Returns whether the light links changed.
bool Solver::refine_light_links(double threshold) {
  if (light_links_.empty()) return false;
  const auto& lights = scene_.lights;
  std::vector<std::uint8_t> split(light_links_.size(), 0);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, light_links_.size()), [&](const auto& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const LightLink& l = light_links_[i];
      const Element& p = hierarchy_.element(l.receiver);
      const double brightness = luminance(hierarchy_.reflectance(p) * lights[l.light].colour);
      // Light the samples miss splits the receiver when it would show (a
      // hundredth of the adaptation level) whatever the oracle: the oracle
      // can only judge what the samples see.
      const bool missed = brightness * l.missed > kMissedLight * reference_radiance_;
      split[i] = p.is_leaf() &&
                 (missed || brightness / reference_radiance_ * l.oracle > threshold) &&
                 can_split(l.receiver);
    }
  });
  for (size_t i = 0; i < light_links_.size(); ++i) {
    if (!split[i] || !hierarchy_.element(light_links_[i].receiver).is_leaf()) continue;
    if (options_.max_elements && hierarchy_.elements().size() + 4 > *options_.max_elements) {
      budget_hit_ = true;
      break;
    }
    hierarchy_.subdivide(light_links_[i].receiver);
  }
  std::vector<LightLink> kept, fresh;
  for (const LightLink& l : light_links_) {
    const Element& p = hierarchy_.element(l.receiver);
    if (p.is_leaf()) {
      kept.push_back(l);
      continue;
    }
    for (std::int32_t c = p.first_child; c < p.first_child + 4; ++c) {
      LightLink child;
      child.receiver = c;
      child.light = l.light;
      fresh.push_back(child);
    }
  }
  if (fresh.empty()) return false;
  std::vector<LightLink> made = evaluate_light_links(std::move(fresh));
  for (const LightLink& l : made) hierarchy_.element(l.receiver).has_links = 1;
  kept.insert(kept.end(), made.begin(), made.end());
  light_links_ = std::move(kept);
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
  if (cluster_links_.empty()) return;
  far_light_.resize(static_cast<size_t>(scene_.patches.size()) *
                    2);  // top-level elements come first
  cluster_gather_(clusters_, cluster_links_, hierarchy_, source_, far_light_);
}

// One Jacobi iteration: the links read the radiances as they are now.
double Solver::gather_push_pull() {
  group_links();
  balance_.sent_radiances(hierarchy_, source_);
  gather_far_light();
  gather_direct_light();
  return push_pull(hierarchy_, LinkGather{hierarchy_, links_, offset_, order_, source_}, far_light_,
                   balance_.down_scale(), direct_light_);
}

// Refine, gather, push/pull until converged (or `max_iterations`). Returns the
// last residual.
double Solver::iterate(double threshold, int max_iterations, double tolerance) {
  double residual = 0.0;
  // Radiance change since refinement last found nothing to do: decisions can
  // only change once the radiances they read have moved (a converging
  // high-albedo scene iterates hundreds of times without new refinement).
  double drift = std::numeric_limits<double>::infinity();
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
  source_.resize(hierarchy_.elements().size(), Rgb(0.0));
  group_links();
  gather_far_light();
  gather_direct_light();
  push_pull(hierarchy_, LinkGather{hierarchy_, links_, offset_, order_, source_}, far_light_,
            balance_.down_scale(), direct_light_, &leaf);
  result_.mesh = make_output_mesh(hierarchy_, leaf);
  stats_.threshold = threshold;
}

SolveResult Solver::run() {
  report("linking", 0.0);
  link_initially();
  const bool fixed_bounces = options_.bounces.has_value();
  const double target = quality_threshold(options_.oracle, options_.quality);

  // Threshold of each pass: pass 0 solves without refinement, later passes
  // lower the threshold geometrically to the target. Fixed bounces: one pass.
  std::vector<double> thresholds;
  if (fixed_bounces) {
    thresholds.push_back(target);
  } else {
    thresholds.push_back(std::numeric_limits<double>::infinity());
    if (std::isfinite(target)) {
      const int steps = std::max(1, static_cast<int>(std::ceil(6 * options_.quality)));
      for (int k = 1; k <= steps; ++k) {
        thresholds.push_back(quality_threshold(options_.oracle, options_.quality * k / steps));
      }
    }
  }
  passes_ = static_cast<int>(thresholds.size());
  stats_.stopped_by = "quality";
  if (!cancelled()) snapshot(std::numeric_limits<double>::infinity());  // emitters only
  for (pass_ = 0; pass_ < passes_; ++pass_) {
    if (cancelled()) break;
    threshold_ = thresholds[static_cast<size_t>(pass_)];
    const bool last = pass_ + 1 == passes_;
    if (fixed_bounces) {
      iterate(threshold_, *options_.bounces, -1.0);
    } else {
      iterate(threshold_, options_.max_iterations, last ? options_.tolerance : 1e-3);
    }
    if (pass_abandoned()) break;
    snapshot(threshold_);
    stats_.passes = pass_ + 1;
    report("pass", (pass_ + 1.0) / passes_);
    if (budget_hit_) {
      stats_.stopped_by = memory_hit_ ? "memory" : "max_elements";
      break;
    }
    if (out_of_time()) {
      stats_.stopped_by = "time_budget";
      break;
    }
  }
  if (refinement_cut_short_) stats_.stopped_by = "time_budget";
  if (cancelled()) {
    stats_.cancelled = true;
    stats_.stopped_by = "cancel";
  }
  const auto& elements = hierarchy_.elements();
  stats_.elements = elements.size();
  stats_.leaves = static_cast<size_t>(std::count_if(elements.begin(), elements.end(),
                                                    [](const Element& e) { return e.is_leaf(); }));
  stats_.links = links_.size();
  stats_.cluster_links = cluster_links_.size();
  stats_.light_links = light_links_.size();
  stats_.skipped_faces = scene_.skipped.size();
  stats_.repaired_faces = scene_.repaired.size();
  track_memory();
  stats_.seconds = elapsed();
  result_.stats = stats_;
  report("done", 1.0);
  return std::move(result_);
}

}  // namespace

std::size_t estimated_base_bytes(const Scene& scene) {
  // Per patch: two sides' elements with their gather state, the cluster tree
  // (about two nodes per side), and Embree's BVH (about 128 bytes a primitive).
  constexpr std::size_t kPerSide = sizeof(Element) + 2 * sizeof(ClusterNode) + 4 * sizeof(Rgb);
  constexpr std::size_t kPerPatch = sizeof(Patch) + 2 * kPerSide + 128;
  return scene.patches.size() * kPerPatch;
}

std::optional<SolveOptions::LeafLinks> parse_leaf_links(std::string_view name) {
  if (name == "none") return SolveOptions::LeafLinks::None;
  if (name == "near") return SolveOptions::LeafLinks::Near;
  if (name == "all") return SolveOptions::LeafLinks::All;
  return std::nullopt;
}

std::string_view leaf_links_name(SolveOptions::LeafLinks links) {
  switch (links) {
    case SolveOptions::LeafLinks::None:
      return "none";
    case SolveOptions::LeafLinks::Near:
      return "near";
    case SolveOptions::LeafLinks::All:
      return "all";
  }
  return "unknown";
}

double quality_threshold(Oracle oracle, double quality) {
  if (!(quality > 0.0)) return std::numeric_limits<double>::infinity();
  const ThresholdRange range = threshold_range(oracle);
  const double q = std::min(quality, 1.0);
  return range.coarse * std::pow(range.fine / range.coarse, q);
}

SolveResult solve(const Scene& scene, const SolveOptions& options, const ProgressCallback& progress,
                  const CancelCheck& cancel) {
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
  SolveResult result =
      arena.execute([&] { return Solver(scene, checked, progress, cancel).run(); });
  require_finite(result.mesh);
  return result;
}

}  // namespace radiosity
