// The boundary's guarantee: an output mesh with any non-finite value is an
// error naming the input face, never a result.
#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>
#include <string>

#include "core/hierarchy/make_output_mesh.h"

namespace radiosity {
namespace {

// Two triangles over four vertices, from input faces 7 (front) and 9 (back).
OutputMesh two_triangles() {
  OutputMesh m;
  m.positions = {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0};
  m.face_vertices = {0, 1, 2, 0, 2, 3};
  m.face_sizes = {3, 3};
  m.radiance.assign(12, 0.5f);
  m.vertex_irradiance.assign(12, 0.25f);
  m.source_face = {7, 9};
  m.source_side = {0, 1};
  m.irradiance.assign(6, 0.25f);
  return m;
}

std::string error_of(const OutputMesh& m) {
  try {
    require_finite(m);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

TEST(RequireFinite, AcceptsAFiniteMesh) { EXPECT_EQ(error_of(two_triangles()), ""); }

TEST(RequireFinite, NamesTheFaceOfEachKindOfValue) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  OutputMesh radiance = two_triangles();
  radiance.radiance[3 * 3 + 1] = nan;  // vertex 3: only in the second triangle
  EXPECT_NE(error_of(radiance).find("non-finite radiance on input face 9 (back side"),
            std::string::npos)
      << error_of(radiance);
  OutputMesh position = two_triangles();
  position.positions[1 * 3] = std::numeric_limits<double>::infinity();  // vertex 1: first triangle
  EXPECT_NE(error_of(position).find("non-finite position on input face 7 (front side"),
            std::string::npos);
  OutputMesh irradiance = two_triangles();
  irradiance.irradiance[5] = -std::numeric_limits<float>::infinity();
  EXPECT_NE(error_of(irradiance).find("non-finite irradiance on input face 9"), std::string::npos);
  OutputMesh gathered = two_triangles();
  gathered.vertex_irradiance[0] = nan;
  EXPECT_NE(error_of(gathered).find("non-finite vertex irradiance on input face 7"),
            std::string::npos);
}

}  // namespace
}  // namespace radiosity
