// Gather and push/pull (DESIGN s5): what every element gathers through its
// own links, per sample, pushed down the hierarchy with each element's
// interpolant and pulled up as area averages. One call is one Jacobi
// iteration: the links read the radiances the previous one left.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/link_transport.h"
#include "radiosity/color.h"

namespace radiosity {

// What an element gathers through its own links, per sample: H[s] = sum of
// F_s L_q over its links, with the emitters' radiances as `source` holds them.
struct LinkGather {
  const Hierarchy& hierarchy;
  const std::vector<Link>& links;
  const std::vector<std::uint32_t>&
      offset;  // links of element e: order[offset[e] .. offset[e + 1])
  const std::vector<std::uint32_t>& order;
  const std::vector<Rgb>& source;

  std::array<Rgb, kMaxSamples> operator()(std::int32_t e) const;
};

using SampleRgb = std::array<Rgb, kMaxSamples>;
using SampleScale = std::array<float, kMaxSamples>;

// The values a split element hands its four children at their samples: its
// interpolant there, shifted uniformly so that the children carry the same
// total as the parent (pushing light down neither makes nor loses energy).
std::array<SampleRgb, 4> push_to_children(const Hierarchy& hierarchy, const Element& parent,
                                          const SampleRgb& total);

// What every leaf gathers at its samples, its own links plus everything its
// ancestors gathered pushed down, without touching radiances. `far_light`:
// what each top-level element gathers through cluster links, at its samples
// (or empty). Indexed by element; zero for inner elements.
std::vector<SampleRgb> gathered_at_leaves(const Hierarchy& hierarchy, const LinkGather& gather,
                                          const std::vector<SampleRgb>& far_light);

// One push/pull over every root: each leaf's radiance becomes L_e + rho H
// (H the interpolant's average of what it gathered), each inner element's the
// area average of its children's. Returns the relative change of radiance,
// area-weighted over leaves. `down_scale` (per element, may be empty) scales
// what each leaf sample receives from its ancestors (energy_balance.h).
// `direct` (per element, may be empty) is what each element gathers from the
// lights that are not surfaces (direct_light.h), at its samples.
// `by_rays` (per top-level element, may be empty) is what it gathers by rays,
// uniform over it (dim_sides.h).
// `leaf_out`, if given, receives what each leaf gathered at its samples (for
// the output mesh).
double push_pull(Hierarchy& hierarchy, const LinkGather& gather,
                 const std::vector<SampleRgb>& far_light,
                 const std::vector<SampleScale>& down_scale, const std::vector<SampleRgb>& direct,
                 const std::vector<Rgb>& by_rays, std::vector<SampleRgb>* leaf_out = nullptr);

}  // namespace radiosity
