// Exact visibility where it can show (issue 32): a sample whose light from a
// link is faint next to the light its side gathers is shadowed by rays.
//
// The exact visible polygon at a sample costs tens of microseconds with a
// few hundred occluders in the shaft, and most links of a dense scene carry
// a sliver of their receiver's light: a face of a subdivided head linked to
// each of a thousand faces around it. A sample whose unoccluded light from a
// link (the emitter side's radiance times the sample's unoccluded form
// factor) is below a share (SolveOptions::faint_share) of what its side
// gathered in the ray pass takes its visible form factor from stratified
// shadow rays instead (sampled_visibility.h): an error of a few percent of a
// faint contribution is an error below that share of the sample's light,
// uncorrelated from link to link. The lamps, the sky's and the bright walls'
// light, where shadows are seen, stay exact.
//
// Both radiances are the ray pass's, fixed for the solve: which samples take
// rays depends on the geometry and the lighting, never on the order of work.
#pragma once

#include <cstdint>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/ray_pass.h"

namespace radiosity {

class FaintSamples {
 public:
  FaintSamples() = default;
  // From a complete ray pass; none (every sample exact) when share is 0 or
  // the pass did not finish.
  FaintSamples(const Hierarchy& hierarchy, const RayPass& pass, double share);

  bool empty() const { return sends_.empty(); }

  // Top-level elements (Hierarchy::root of the element's patch side).
  // `form_factor`: the sample's unoccluded form factor to the emitter.
  bool faint(std::int32_t receiver_side, std::int32_t emitter_side, double form_factor) const {
    return sends_[static_cast<std::size_t>(emitter_side)] * form_factor <
           below_[static_cast<std::size_t>(receiver_side)];
  }

  std::size_t memory_bytes() const {
    return (sends_.capacity() + below_.capacity()) * sizeof(float);
  }

 private:
  // Per top-level element: the luminance it sends (L_e + rho H of the ray
  // pass), and the share of what it gathers (H) below which light is faint.
  std::vector<float> sends_, below_;
};

}  // namespace radiosity
