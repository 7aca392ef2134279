// Scenes for the C++ tests, built from arrays as the Python API builds them.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "radiosity/scene.h"

namespace radiosity::test {

// Faces added one at a time, then made into a Scene.
struct Arrays {
  std::vector<double> positions;
  std::vector<std::int64_t> faces, sizes;
  std::vector<double> reflectance, emission;
  std::vector<std::uint8_t> two_sided;

  // An axis-aligned square of side `a` at `origin`, facing +z or -z.
  void square(const dvec3& origin, double a, bool up, double rho, double emit,
              bool both_sides = false) {
    const auto base = static_cast<std::int64_t>(positions.size() / 3);
    const dvec3 c[4] = {origin, origin + dvec3(a, 0, 0), origin + dvec3(a, a, 0),
                        origin + dvec3(0, a, 0)};
    for (int k = 0; k < 4; ++k) {
      const dvec3& p = c[up ? k : 3 - k];
      positions.insert(positions.end(), {p.x, p.y, p.z});
    }
    for (int k = 0; k < 4; ++k) faces.push_back(base + k);
    sizes.push_back(4);
    reflectance.insert(reflectance.end(), {rho, rho, rho});
    emission.insert(emission.end(), {emit, emit, emit});
    two_sided.push_back(both_sides ? 1 : 0);
  }
  // A planar quad through four corners (counter-clockwise about its front).
  void quad(const std::array<dvec3, 4>& corners, double rho, double emit) {
    const auto base = static_cast<std::int64_t>(positions.size() / 3);
    for (const dvec3& p : corners) positions.insert(positions.end(), {p.x, p.y, p.z});
    for (int k = 0; k < 4; ++k) faces.push_back(base + k);
    sizes.push_back(4);
    reflectance.insert(reflectance.end(), {rho, rho, rho});
    emission.insert(emission.end(), {emit, emit, emit});
    two_sided.push_back(0);
  }
  Scene scene() const {
    return make_scene({positions, faces, sizes, reflectance, emission, two_sided, {}, {}, {}});
  }
};

}  // namespace radiosity::test
