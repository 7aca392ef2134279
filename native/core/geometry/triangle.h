// A triangle of the scene in world space, double precision: the unit of
// occlusion (Section 4.3). Faces are two-sided, so the winding carries no
// meaning for visibility.
#pragma once

#include <array>
#include <cstdint>
#include <limits>

#include "radiosity/vec.h"

namespace radiosity {

// The input face of no triangle: what a query that skips no face passes.
inline constexpr std::uint32_t kNoFace = std::numeric_limits<std::uint32_t>::max();

struct Triangle {
  std::array<dvec3, 3> v{dvec3(0.0), dvec3(0.0), dvec3(0.0)};
};

}  // namespace radiosity
