// Making the output mesh (radiosity/output_mesh.h, which says what it holds)
// from the hierarchy's leaves and what they gathered; output_mesh.cpp.
#pragma once

#include <array>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "radiosity/color.h"
#include "radiosity/output_mesh.h"

namespace radiosity {

// `leaf_irradiance`: what each leaf gathered at its samples (push_pull's leaf_out).
OutputMesh make_output_mesh(const Hierarchy& hierarchy,
                            const std::vector<std::array<Rgb, kMaxSamples>>& leaf_irradiance);

}  // namespace radiosity
