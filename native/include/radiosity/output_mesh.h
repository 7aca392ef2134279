// The solution as a mesh (DESIGN s5): the leaves of every lit patch side as
// polygons over shared vertices, with the hanging vertices of finer neighbours
// inserted into coarser polygons so Gouraud shading shows no cracks, and the
// radiance L_e + rho H at every vertex.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "radiosity/color.h"

namespace radiosity {

struct OutputMesh {
  std::vector<double> positions;            // 3 per vertex
  std::vector<std::int32_t> face_vertices;  // polygons' vertices, concatenated
  std::vector<std::int32_t> face_sizes;     // per polygon
  std::vector<float> radiance;              // 3 per vertex
  // Per vertex: the gathered H (irradiance / pi) before the surface's own
  // reflectance and emission, so radiance = L_e + rho H; what a lighting-only
  // bake multiplies a textured material's colour by.
  std::vector<float> vertex_irradiance;   // 3 per vertex
  std::vector<std::int32_t> source_face;  // per polygon: the input face
  std::vector<std::uint8_t> source_side;  // per polygon: 0 front, 1 back
  // Per polygon: area average of the gathered H (irradiance / pi) over the
  // element, as the solver integrates it: absorbed power is pi (1 - rho) H A.
  std::vector<float> irradiance;  // 3 per polygon

  std::size_t vertex_count() const { return positions.size() / 3; }
  std::size_t polygon_count() const { return face_sizes.size(); }
};

// `leaf_irradiance[e]` holds, for every leaf e, the total gathered H (all
// ancestors' links pushed down plus its own) at its samples.
// The guarantee at the boundary: throws std::runtime_error naming the polygon,
// its input face and side if any position, radiance or irradiance is NaN or
// infinite. Input is range-checked (scene.h), so such a value is a solver bug;
// it must reach the caller as an error, never as a mesh.
void require_finite(const OutputMesh& mesh);

}  // namespace radiosity
