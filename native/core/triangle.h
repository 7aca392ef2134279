// A triangle of the scene in world space, double precision: the unit of
// occlusion (Section 4.3). Faces are two-sided, so the winding carries no
// meaning for visibility.
#pragma once

#include <array>

#include "core/vec.h"

namespace radiosity {

struct Triangle {
  std::array<dvec3, 3> v{dvec3(0.0), dvec3(0.0), dvec3(0.0)};
};

}  // namespace radiosity
