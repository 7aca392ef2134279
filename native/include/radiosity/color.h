// RGB radiance and reflectance, linear. Double precision inside the solver, so
// that scaling a scene's geometry or brightness changes no refinement decision
// through rounding; single precision only in the output.
#pragma once

#include <glm/glm.hpp>

namespace radiosity {

using Rgb = glm::dvec3;

// Brightness of a linear RGB value (Rec. 709 luminance, Blender's default
// scene-linear primaries): how the oracles reduce colour to one number.
inline double luminance(const Rgb& c) { return 0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z; }

}  // namespace radiosity
