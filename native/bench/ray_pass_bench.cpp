// The rough look's cost (core/solve/ray_pass.h) against the scene's size: a
// 20 x 20 x 4 m room lit by a ceiling panel, over a floor of n x n tiles
// (separate faces, as a tessellated mesh would be) and n x n small quads
// floating above it, both sides reflecting. Counters: top-level elements,
// rays per element, and rays (cosine and shadow) per second over all threads.
#include <benchmark/benchmark.h>

#include <cstdint>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/ray_pass.h"
#include "core/visibility/occluders.h"
#include "radiosity/scene.h"

namespace radiosity {
namespace {

struct Arrays {
  std::vector<double> positions, reflectance, emission;
  std::vector<std::int64_t> face_vertices, face_sizes;
  std::vector<std::uint8_t> two_sided;

  void quad(const dvec3& a, const dvec3& b, const dvec3& c, const dvec3& d, double rho, double emit,
            bool both) {
    const auto first = static_cast<std::int64_t>(positions.size() / 3);
    for (const dvec3& p : {a, b, c, d}) positions.insert(positions.end(), {p.x, p.y, p.z});
    for (std::int64_t k = 0; k < 4; ++k) face_vertices.push_back(first + k);
    face_sizes.push_back(4);
    reflectance.insert(reflectance.end(), {rho, rho, rho});
    emission.insert(emission.end(), {emit, emit, emit});
    two_sided.push_back(both ? 1 : 0);
  }
  SceneArrays view() const {
    SceneArrays a;
    a.positions = positions;
    a.face_vertices = face_vertices;
    a.face_sizes = face_sizes;
    a.reflectance = reflectance;
    a.emission = emission;
    a.two_sided = two_sided;
    return a;
  }
};

Scene tiled_room(int n) {
  Arrays a;
  const double s = 20.0, h = 4.0;
  // Walls and ceiling two-sided (their outsides see nothing), the lamp 1 cm
  // under the ceiling facing down.
  a.quad({0, 0, h}, {s, 0, h}, {s, s, h}, {0, s, h}, 0.6, 0.0, true);
  a.quad({0, 0, 0}, {0, 0, h}, {0, s, h}, {0, s, 0}, 0.6, 0.0, true);
  a.quad({s, 0, 0}, {s, s, 0}, {s, s, h}, {s, 0, h}, 0.6, 0.0, true);
  a.quad({0, 0, 0}, {s, 0, 0}, {s, 0, h}, {0, 0, h}, 0.6, 0.0, true);
  a.quad({0, s, 0}, {0, s, h}, {s, s, h}, {s, s, 0}, 0.6, 0.0, true);
  a.quad({9, 9, h - 0.01}, {9, 11, h - 0.01}, {11, 11, h - 0.01}, {11, 9, h - 0.01}, 0.0, 10.0,
         false);
  const double t = s / n;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = i * t, y = j * t;
      a.quad({x, y, 0}, {x + t, y, 0}, {x + t, y + t, 0}, {x, y + t, 0}, 0.6, 0.0, false);
      const double z = 0.5 + 0.5 * ((i + j) % 3), q = 0.3 * t;
      a.quad({x + q, y + q, z}, {x + 2 * q, y + q, z}, {x + 2 * q, y + 2 * q, z},
             {x + q, y + 2 * q, z}, 0.5, 0.0, true);
    }
  }
  return make_scene(a.view());
}

void BM_RayPass(benchmark::State& state) {
  const Scene scene = tiled_room(static_cast<int>(state.range(0)));
  const Hierarchy hierarchy(scene);
  const SceneOccluders occluders = make_scene_occluders(scene);
  RayPass pass;
  for (auto _ : state) {
    pass = ray_pass(hierarchy, *occluders.rays, {});
    benchmark::DoNotOptimize(pass.gathered.data());
  }
  const auto elements = static_cast<double>(hierarchy.elements().size());
  state.counters["elements"] = elements;
  state.counters["rays_per_element"] = pass.rays;
  state.counters["iterations"] = pass.iterations;
  state.counters["rays_per_second"] =
      benchmark::Counter(2.0 * elements * pass.rays * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_RayPass)->Arg(10)->Arg(50)->Arg(150)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace radiosity

BENCHMARK_MAIN();
