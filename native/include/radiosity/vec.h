// Vector types of the core: GLM in double precision for every geometric kernel.
#pragma once

#include <glm/glm.hpp>

namespace radiosity {

using glm::dmat3;
using glm::dvec2;
using glm::dvec3;

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr double kInvTwoPi = 1.0 / (2.0 * kPi);

}  // namespace radiosity
