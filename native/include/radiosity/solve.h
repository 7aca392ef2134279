// Hierarchical radiosity (Hanrahan, Salzman and Aupperle 1991) with a pluggable
// refinement oracle (DESIGN s5-6): initial links between facing top-level
// patches, then passes of decreasing threshold, each iterating
// refine -> gather -> push/pull until the radiance converges. Every pass reuses
// the elements and links already made, so the solve can stop at any time (a
// budget, or cancel) with the best complete solution so far.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>

#include "radiosity/output_mesh.h"
#include "radiosity/scene.h"

namespace radiosity {

// More worker threads than any machine this runs on has cores.
inline constexpr int kMaxThreads = 1024;
// Shadow rays per sample point and emitter in sampled visibility: at most this.
inline constexpr int kMaxRays = 65536;

// Thrown before any work when even the unrefined solve would not fit in the
// memory limit (Python: MemoryError, with this message).
struct InsufficientMemory : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Bytes an unrefined solve of `scene` needs at least (patches, elements, the
// cluster tree and the ray-tracing structure): the estimate the memory limit
// is checked against before allocating.
std::size_t estimated_base_bytes(const Scene& scene);

// What decides where to refine (DESIGN s6; core/solve/oracle.h has the criteria).
enum class Oracle : std::uint8_t {
  Standard,    // BF: (F_max - F_min) A_p                              (eq. 6)
  Perceptual,  // k max r_ij, from values and tangential slopes        (eqs. 25-28)
  Gradient,    // max |pr(grad F_i) - pr(grad F_j)| A_p                (eqs. 18-20)
  // The error of the mesh's linear reconstruction (from the same samples as
  // Perceptual) in just noticeable differences: Weber contrast against the
  // receiver's radiance, fading for elements smaller than the eye resolves.
  Noticeable,
};
// Every oracle, in the order the add-on lists them.
inline constexpr std::array<Oracle, 4> kOracles = {Oracle::Standard, Oracle::Perceptual,
                                                   Oracle::Gradient, Oracle::Noticeable};

// How partly occluded links see their emitter: the exact visible polygon, or
// shadow rays.
enum class VisibilityMode : std::uint8_t { Exact, Sampled };

struct SolveOptions {
  // Noticeable reaches a given error soonest (the study: 0.21 to 0.73 times
  // the standard oracle's time at equal DoG error, perceptual 0.82 to 2.36),
  // and keeps its brightness at coarse meshes: a closed textured room at
  // quality 0.5 came out -0.2 % from Cycles in exposure, perceptual +3.8 %.
  Oracle oracle = Oracle::Noticeable;
  // 0 = no refinement (the coarsest solution), 1 = the finest the oracle's
  // threshold scale allows; see quality_threshold().
  double quality = 0.5;
  std::optional<std::size_t> max_elements;  // element budget
  std::optional<double> time_budget;        // seconds, on `clock`
  // Seconds from any fixed origin, read for the time budget and the result's
  // `seconds`; empty: the steady clock. Tests give a fake one, so that what a
  // budget stops does not depend on the machine's speed or load.
  std::function<double()> clock;
  // Bytes the elements and links may hold; refinement stops there (stopped_by
  // "memory"), and a scene whose unrefined solve cannot fit is refused before
  // any allocation. Default: 3/4 of the memory available when the solve starts.
  std::optional<std::size_t> memory_limit;
  VisibilityMode visibility = VisibilityMode::Exact;
  int rays = 16;  // in [1, kMaxRays]
  // When set: one pass at the target threshold, with exactly this many
  // refine/gather/push-pull iterations from L = L_e (the source's 3-iteration runs).
  std::optional<int> bounces;
  std::optional<int> threads;  // in [1, kMaxThreads]; default: all cores
  // Run the solve's threads at a lower CPU priority than the caller's other
  // threads (an interactive interface beside the solve; core/solve/yield_priority.h).
  bool yield_to_interface = false;
  // Smallest element, as a fraction of the scene's total area (1e-5 of an
  // 80 m2 room is a 3 cm square).
  double min_element_area = 1e-5;
  // Which links a split receiver hands down to its children, to be gathered
  // at their own samples instead of pushed down as interpolated values
  // (native/README.md): none (textbook HR), near-field ones (the emitter is
  // closer than the receiver's size), or all, with near-field links from a
  // split emitter handed to its children too (conserves energy to 1e-3, 3 to
  // 5 times more links).
  enum class LeafLinks : std::uint8_t { None, Near, All };  // "none", "near", "all"
  LeafLinks leaf_links = LeafLinks::Near;
  // Clusters of patch sides whose centres are further apart than this many
  // times the sum of their radii exchange light through one cluster link
  // (cluster_links.h); infinity: every pair of patch sides is linked;
  // 0: from the quality, 2 at 0 to 10 at 1.
  double cluster_separation = 0.0;
  // Sides no ray of the first look brought direct light to, and whose light
  // there is below this share of the mean, gather by rays instead of links
  // (dim_sides.h); 0: every side light reaches is linked.
  double dim_share = 0.02;
  // With exact visibility and the standard or Noticeable oracle: a sample
  // whose unoccluded light from a link is below this share of what its side
  // gathered in the ray pass is shadowed by `rays` shadow rays instead
  // (faint_samples.h); 0: every sample exact.
  double faint_share = 0.02;
  double tolerance = 1e-6;  // relative change of radiance that counts as converged
  int max_iterations = 5000;
};

// What the solve is doing when it reports progress.
enum class SolvePhase : std::uint8_t {
  Linking,    // the initial links
  Refining,   // a round of refinement made new links
  Gathering,  // an iteration gathered light over the links
  Pass,       // a pass ended: its solution stands
  Done,
};

// Why the solve stopped.
enum class StopReason : std::uint8_t { Quality, MaxElements, Memory, TimeBudget, Cancel };

// Why a solve given a SolveReuse did not relight the solve it keeps.
enum class RelightRefusal : std::uint8_t {
  None,           // it could (and did)
  NothingKept,    // no complete solve was kept yet
  OracleChanged,  // options the links were made with changed: ...
  QualityChanged,
  VisibilityChanged,       // the visibility mode, its rays or faint_share
  FixedBounces,            // a fixed number of bounces was asked (then or now)
  SmallestElementChanged,  // min_element_area
  LinkingChanged,          // leaf_links, cluster_separation or dim_share
  GeometryChanged,
  LightsAddedOrRemoved,  // or turned on or off (a light that gives nothing is left out)
  LightChanged,          // a light moved or changed shape
  NowEmits,              // a surface that did not emit light does
  NowReflects,           // a black surface now reflects light
};

// The names of the options' and reports' values, as the Python API and the
// add-on spell them ("perceptual", "exact", "near", "refining", "time_budget"):
// one table per enum (core/solve/solve_options.cpp).
std::optional<Oracle> parse_oracle(std::string_view name);
std::string_view oracle_name(Oracle oracle);
std::optional<VisibilityMode> parse_visibility(std::string_view name);
std::string_view visibility_name(VisibilityMode mode);
std::optional<SolveOptions::LeafLinks> parse_leaf_links(std::string_view name);
std::string_view leaf_links_name(SolveOptions::LeafLinks links);
std::string_view phase_name(SolvePhase phase);
std::string_view stop_reason_name(StopReason reason);
std::string_view relight_refusal_name(RelightRefusal refusal);  // "" for None

// SolveOptions{} and the limits as a JSON object, by the names above, and the
// oracles' names in kOracles' order ("oracles"): the defaults and choices the
// add-on's settings start from (solver_defaults.json, written at
// build time by native/generate/write_defaults.cpp) and `_radiosity.DEFAULTS_JSON`.
std::string defaults_json();

struct SolveResult;

// What a progress callback is told. `passes` is fixed from the first report;
// `fraction` never decreases; the Done report's counts are the result's.
struct SolveProgress {
  int pass = 0;
  int passes = 0;
  SolvePhase phase = SolvePhase::Linking;
  std::size_t elements = 0;
  std::size_t leaves = 0;
  std::size_t links = 0;
  double threshold = 0.0;
  double seconds = 0.0;
  double fraction = 0.0;  // overall progress in [0, 1]: linking is the first tenth, then passes
  // With phase Pass: that pass's solution, as solve() would return it if it
  // stopped there (valid during the call only; copy what is kept).
  const SolveResult* pass_result = nullptr;
};

// CPU seconds spent in each part of link evaluation (summed over threads), and
// how many form factors were computed: clear of occluders, through the visible
// polygon or shadow rays (occluded; of them, by rays where exact visibility
// found the sample's light faint: faint_samples.h), or taken from a sibling
// (CornerMemo).
struct LinkTimings {
  double visibility = 0.0;
  double form_factors = 0.0;
  double oracle = 0.0;
  std::uint64_t samples_clear = 0;
  std::uint64_t samples_occluded = 0;
  std::uint64_t samples_faint = 0;
  std::uint64_t samples_shared = 0;
  // Points of the energy correction's 3 x 3 grid (link_transport.cpp) shadowed
  // by rays because the link's light is faint there.
  std::uint64_t grid_points_faint = 0;
  LinkTimings& operator+=(const LinkTimings& o) {
    visibility += o.visibility;
    form_factors += o.form_factors;
    oracle += o.oracle;
    samples_clear += o.samples_clear;
    samples_occluded += o.samples_occluded;
    samples_faint += o.samples_faint;
    samples_shared += o.samples_shared;
    grid_points_faint += o.grid_points_faint;
    return *this;
  }
};

struct SolveStats {
  std::size_t elements = 0;
  std::size_t leaves = 0;
  std::size_t links = 0;
  std::size_t cluster_links = 0;
  std::size_t light_links = 0;  // leaf and light pairs of direct light (direct_light.h)
  int passes = 0;
  int iterations = 0;
  double residual = 0.0;   // relative change of the last iteration
  double threshold = 0.0;  // of the last complete pass
  std::size_t skipped_faces = 0;
  std::size_t repaired_faces = 0;  // solved after a repair (Scene::repaired)
  bool cancelled = false;
  bool reused = false;  // relit with the elements and links of a kept solve (SolveReuse)
  // With a SolveReuse not reused: why (SolveReuse::refusal).
  RelightRefusal reuse_refusal = RelightRefusal::None;
  StopReason stopped_by = StopReason::Quality;
  double seconds = 0.0;
  double seconds_linking = 0.0;
  double seconds_clustering = 0.0;  // of linking: the walk over cluster pairs, with its rays
  double seconds_ray_pass = 0.0;    // the rough look before linking (ray_pass.h)
  int ray_pass_rays = 0;            // its rays per reflecting top-level element
  std::size_t unlit_sides = 0;      // top-level sides it found no light reaches: not linked
  std::size_t dim_sides = 0;  // top-level sides too dim to link: they gather by rays (dim_sides.h)
  LinkTimings link_cpu;       // CPU seconds over all threads
  double seconds_gather = 0.0;  // gather and push/pull, wall clock
  std::size_t element_bytes = 0;
  std::size_t link_bytes = 0;
  std::size_t peak_bytes = 0;  // peak of the solver's own structures
};

struct SolveResult {
  OutputMesh mesh;
  SolveStats stats;
};

// Thresholds of the oracle at a quality level: log-spaced from the largest
// (quality -> 0) to the smallest (quality = 1). Quality 0 means no refinement.
double quality_threshold(Oracle oracle, double quality);

using ProgressCallback = std::function<void(const SolveProgress&)>;

// Polled often from the solving thread; true stops the solve.
using CancelCheck = std::function<bool()>;

// The elements and links of the last complete solve, kept so that a change of
// lighting alone (emission, reflectance, the lights' colours and strengths)
// solves again without linking: form factors and visibility depend on the
// geometry only. solve() with a SolveReuse relights when it can (refusal() is
// empty) and otherwise solves from nothing and keeps that. It holds the
// solve's memory until cleared or destroyed. One solve at a time may use it.
class SolveReuse {
 public:
  SolveReuse();
  ~SolveReuse();
  SolveReuse(const SolveReuse&) = delete;
  SolveReuse& operator=(const SolveReuse&) = delete;

  bool holds() const { return kept_ != nullptr; }
  void clear();
  std::size_t memory_bytes() const;
  // Why `scene` cannot be relit with `options` from what is kept (None if it
  // can): nothing kept; options other than the limits changed; the geometry
  // changed; a light was added, removed, turned on or off; a surface emits or
  // reflects that did not before (the links it needs were never made).
  RelightRefusal refusal(const Scene& scene, const SolveOptions& options) const;

 private:
  friend SolveResult solve(const Scene&, const SolveOptions&, const ProgressCallback&,
                           const CancelCheck&, SolveReuse*);
  struct Kept;
  std::unique_ptr<Kept> kept_;
};

// Solves; throws std::invalid_argument for bad options. When `cancelled`
// turns true (set from another thread) the solve returns the last complete
// pass promptly. With `reuse`: relights from it when it can, and keeps this
// solve in it if it completes (or clears it).
SolveResult solve(const Scene& scene, const SolveOptions& options,
                  const ProgressCallback& progress = {}, const CancelCheck& cancelled = {},
                  SolveReuse* reuse = nullptr);

}  // namespace radiosity
