// The refinement policy shared by every oracle (DESIGN s5): which links are
// worth splitting, which end to split, and what a split does to the links.
// The solver (solver.cpp) runs rounds of it until nothing is above the
// threshold; everything here is a function of the hierarchy and the links,
// so it is tested on its own (refine_test.cpp).
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/direct_light.h"
#include "core/solve/link_transport.h"
#include "core/solve/oracle.h"
#include "radiosity/solve.h"

namespace radiosity {

enum class Split : std::uint8_t { None, Receiver, Emitter };

// How small elements may get and how many there may be.
struct RefineLimits {
  double min_area = 0.0;  // an element is split only if its children are at least this large
  std::optional<std::size_t> max_elements;

  bool can_split(const Hierarchy& hierarchy, std::int32_t e) const {
    return hierarchy.element(e).area / 4.0 >= min_area;
  }
  // Would one more split (four children) exceed the element budget?
  bool budget_full(const Hierarchy& hierarchy) const {
    return max_elements && hierarchy.elements().size() + 4 > *max_elements;
  }
};

// The radiance thresholds are relative to: the mean radiance of the lit and
// emitting sides as the solution stands (solver's reference brightness).
double adaptation_radiance(const Hierarchy& hierarchy);

// Each element's luminance relative to the adaptation level: what the oracles'
// decisions read (a light made brighter scales every radiance and changes none).
std::vector<double> relative_luminance(const Hierarchy& hierarchy);

// How far the relative luminances moved since `before` (relative_luminance of
// the same elements): the area-weighted mean change over the mean, as the
// solve's residual measures change. Below 1e-3, refinement decisions stand.
double relative_luminance_change(const Hierarchy& hierarchy, const std::vector<double>& before);

// What a link's brightness x oracle value is divided by before it is compared
// with the threshold (oracle_reference): the adaptation radiance, or for
// Noticeable one just noticeable difference at the receiver.
struct DecisionScale {
  Oracle oracle = Oracle::Standard;
  double adaptation = 1.0;  // adaptation_radiance()

  double at(const Element& receiver) const {
    return oracle_reference(oracle, adaptation, luminance(receiver.radiance));
  }
};

// Is one end of the link closer to the other than twice its own radius?
bool near_field(const Hierarchy& hierarchy, const Link& link, bool receiver_end);

// Which end of the link to split at this threshold, if any.
Split choose_split(const Hierarchy& hierarchy, const Link& link, double threshold,
                   const DecisionScale& scale, const RefineLimits& limits);

// The decision for every link (in parallel; the same for any thread count).
std::vector<Split> choose_splits(const Hierarchy& hierarchy, std::span<const Link> links,
                                 double threshold, const DecisionScale& scale,
                                 const RefineLimits& limits);

// One round of splitting: the links that stay, and the unevaluated links made
// by the splits (four per split link, consecutive, in link order).
struct SplitLinks {
  std::vector<Link> kept;
  std::vector<Link> fresh;
  bool budget_hit = false;  // a split was refused: the element budget is full
};

// Subdivides the chosen ends in link order (deterministic) within the element
// budget, and replaces each split link by its four children's.
SplitLinks split_links(Hierarchy& hierarchy, std::span<const Link> links,
                       std::span<const Split> decision, const RefineLimits& limits);

// Hands links whose receiver has been split down to its children, so their
// samples' values are gathered, not interpolated from a coarser element
// (SolveOptions::leaf_links); fresh links too: their ends may have been split
// by another link. Moved links join `fresh`, to be evaluated.
void hand_down_links(const Hierarchy& hierarchy, SolveOptions::LeafLinks leaf_links,
                     SplitLinks& links);

// Light links: splits the receivers of those above the threshold (or missing
// light that would show), within the budget. Returns whether the budget
// refused a split.
bool split_light_receivers(Hierarchy& hierarchy, std::span<const Light> lights,
                           std::span<const LightLink> links, double threshold,
                           const DecisionScale& scale, const RefineLimits& limits);

// Replaces every light link whose receiver has been split by its four
// children's (unevaluated, returned); the others stay in `links`.
std::vector<LightLink> hand_down_light_links(const Hierarchy& hierarchy,
                                             std::vector<LightLink>& links);

}  // namespace radiosity
