// How a link's light is spread over its emitter (DESIGN s5). A link whose
// emitter is coarse would send the emitter's average radiance with its average
// form factor; where the part of the emitter that sees the receiver best is
// also brighter or darker than the average (a wall near a corner it lights),
// energy is made or lost: summed over all its links, a small region of such an
// emitter sent between 0.7 and 1.3 times what it reflects. A link therefore
// keeps how its form factor is shared between the emitter's four children
// (the unoccluded F from each child's centre to the receiver, over their
// mean), and a split emitter sends its children's radiances in those shares.
#pragma once

#include <array>
#include <span>
#include <vector>

#include "core/hierarchy/hierarchy.h"

namespace radiosity {

// Per child of the emitter, four times its share of the light the link
// carries: its share of the emitter's area times its form factor to the
// receiver over the emitter's (area-weighted) mean; all ones for four equal
// children that see the receiver alike. Half precision: 1e-3 of a child's
// share is far below what matters, and sending and its bookkeeping
// (energy_balance.cpp) read the same rounded numbers.
using EmitterShape = std::array<_Float16, 4>;
inline constexpr EmitterShape kShapeNotComputed{-1, -1, -1, -1};
inline bool shape_computed(const EmitterShape& shape) { return shape[0] >= 0; }

// The shape of the unoccluded form factor from the emitter's children to the
// receiver polygon (the children's area shares alone where it is zero
// everywhere, or where the emitter reflects nothing: its radiance is then
// uniform).
EmitterShape emitter_shape(const Hierarchy& hierarchy, const Element& emitter,
                           std::span<const dvec3> receiver_polygon);

// What `emitter` sends along a link of this shape: its radiance if it is a
// leaf, else its children's radiances in the shape's shares (its own radiance
// while the shape is not computed).
Rgb sent_radiance(const Hierarchy& hierarchy, std::int32_t emitter,
                  const std::vector<Rgb>& radiance, const EmitterShape& shape);

}  // namespace radiosity
