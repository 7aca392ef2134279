// Sides too dim to link (issue 32): they gather by the ray pass's rays.
//
// Every face of a mesh is two-sided, so a closed object has an inside, and
// the inside of a dense one (a subdivided head lit only through its eyes and
// mouth) faces itself at every distance: its pairs were most of the links of
// such a scene, for light a hundredth of the room's. A side is dim when no ray
// of the ray pass brought it direct light (an emitter's, a light's or the
// sky's) and what it gathered there is below a share (SolveOptions::dim_share,
// 2 %) of the area-weighted mean of the sides light reaches. Such a side is left out of linking and
// gathers instead from what its rays met, at every iteration, as the ray
// pass did (a ray-traced form factor: Sbert 1993, Bekaert 1999): the mean of
// the radiances of the sides its rays met. The sides that are linked gather
// from the dim ones the same way, through their rays that met one, so the
// light a dim side reflects still leaves through the openings. Both read the
// solution as it stands, so a relight (new reflectances, emission, lights)
// needs no new rays: the rays depend on the geometry only.
//
// What it gives up: a dim side's light is uniform over it and carries the
// noise of its few dozen rays; it is never refined.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/ray_pass.h"
#include "radiosity/color.h"

namespace radiosity {

class DimSides {
 public:
  DimSides() = default;
  // From a complete ray pass; none when the pass found no dim side.
  // `share`: of the mean light, what a dim side's stays below (SolveOptions::dim_share).
  DimSides(const Hierarchy& hierarchy, const RayPass& pass, double share);

  // Per top-level element: 1 where it is dim (empty when none is).
  const std::vector<std::uint8_t>& dim() const { return dim_; }
  std::size_t count() const { return count_; }
  bool empty() const { return count_ == 0; }

  // Per top-level element: the share of its rays that met a dim side (for
  // the energy balance, light that leaves by rays, not by links).
  const std::vector<float>& share_to_dim() const { return share_to_dim_; }

  // Sets `light` (per top-level element, uniform over it) to what each side
  // gathers by its rays from the radiances as they stand: for a dim side
  // from every side its rays met, for any other from the dim sides only.
  void gather(const Hierarchy& hierarchy, std::vector<Rgb>& light) const;

  std::size_t memory_bytes() const;

 private:
  std::vector<std::uint8_t> dim_;
  std::size_t count_ = 0;
  std::vector<float> share_to_dim_;
  // The sides that gather by rays, each with the sides its rays met that it
  // gathers from: met_[first_[i], first_[i + 1]) for receiver_[i].
  std::vector<std::int32_t> receiver_;
  std::vector<std::uint32_t> first_;
  std::vector<std::int32_t> met_;
  double per_ray_ = 0.0;  // 1 / the rays per side
};

}  // namespace radiosity
