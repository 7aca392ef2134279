// Costs of visibility (Section 4.3), single thread:
//  - shadow rays per second: our double-precision rays against a link's shaft
//    candidates, and Embree (rtcOccluded1, rtcOccluded8) against the whole scene,
//    on the same rays;
//  - shaft culling: BVH query against a brute-force scan;
//  - microseconds per exact visible-polygon evaluation (F and gradient) against
//    the number of occluders (1, 4, 16, 64);
//  - the sampled mode's cost and its error against the exact F, per ray count.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/visibility/ray_scene.h"
#include "core/visibility/sampled_visibility.h"
#include "core/visibility/shaft.h"
#include "core/visibility/visible_polygon.h"

namespace radiosity {
namespace {

using Polygon = std::vector<dvec3>;

dvec3 uniform_in(std::mt19937_64& rng, const dvec3& lo, const dvec3& hi) {
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  return lo + (hi - lo) * dvec3(uni(rng), uni(rng), uni(rng));
}

// A room-sized clutter: a floor element (receiver) at z = 0, a ceiling element
// (emitter) at z = 3, and 5000 small triangles in [-5, 5]^2 x [0, 3].
struct ClutterScene {
  Polygon receiver{{-0.5, -0.5, 0.0}, {0.5, -0.5, 0.0}, {0.5, 0.5, 0.0}, {-0.5, 0.5, 0.0}};
  Polygon emitter{{-0.5, -0.5, 3.0}, {-0.5, 0.5, 3.0}, {0.5, 0.5, 3.0}, {0.5, -0.5, 3.0}};
  OccluderScene scene;
  std::vector<Triangle> candidates;
  std::vector<dvec3> from, to;  // the shadow rays of the benchmark
  std::unique_ptr<RayScene> rays;

  ClutterScene() {
    std::mt19937_64 rng(1);
    std::vector<Triangle> triangles;
    for (int i = 0; i < 5000; ++i) {
      const dvec3 c = uniform_in(rng, {-5, -5, 0.1}, {5, 5, 2.9});
      Triangle t;
      for (dvec3& v : t.v) v = c + uniform_in(rng, dvec3(-0.1), dvec3(0.1));
      triangles.push_back(t);
    }
    scene = make_occluder_scene(triangles);
    rays = std::make_unique<RayScene>(scene.triangles, scene.face);
    const ShaftCulling culled = cull_shaft(scene, receiver, kNoFace, emitter, kNoFace);
    for (std::uint32_t t : culled.candidates) candidates.push_back(scene.triangles[t]);
    for (int i = 0; i < 4096; ++i) {
      from.push_back(uniform_in(rng, {-0.5, -0.5, 0.0}, {0.5, 0.5, 0.0}));
      to.push_back(uniform_in(rng, {-0.5, -0.5, 3.0}, {0.5, 0.5, 3.0}));
    }
  }
};

const ClutterScene& clutter() {
  static const ClutterScene s;
  return s;
}

// The sampled mode's path: rays from 64 receiver points, 64 rays each, tested
// in double precision against the link's shaft candidates.
void BM_ShadowRays_OwnAgainstShaftCandidates(benchmark::State& state) {
  const ClutterScene& s = clutter();
  EmitterSamples samples;
  samples.weights.assign(64, 1.0);
  double sum = 0.0;
  for (auto _ : state)
    for (std::size_t p = 0; p < 64; ++p) {
      samples.points.assign(s.to.begin() + static_cast<std::ptrdiff_t>(64 * p),
                            s.to.begin() + static_cast<std::ptrdiff_t>(64 * p + 64));
      sum += visible_fraction(s.candidates, s.from[p], samples);
    }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * 4096);
  state.counters["candidates"] = static_cast<double>(s.candidates.size());
  state.counters["scene_triangles"] = static_cast<double>(s.scene.triangles.size());
}
BENCHMARK(BM_ShadowRays_OwnAgainstShaftCandidates)->Unit(benchmark::kMicrosecond);

void BM_ShadowRays_EmbreeOccluded1(benchmark::State& state) {
  const ClutterScene& s = clutter();
  std::size_t blocked = 0;
  for (auto _ : state)
    for (std::size_t i = 0; i < s.from.size(); ++i) blocked += s.rays->occluded(s.from[i], s.to[i]);
  benchmark::DoNotOptimize(blocked);
  state.SetItemsProcessed(static_cast<std::int64_t>(state.iterations() * s.from.size()));
}
BENCHMARK(BM_ShadowRays_EmbreeOccluded1)->Unit(benchmark::kMicrosecond);

// Packets need a shared origin in our API (the sampled mode's case): rays from
// 64 receiver points, 64 rays each.
void BM_ShadowRays_EmbreeOccluded8(benchmark::State& state) {
  const ClutterScene& s = clutter();
  std::vector<std::uint8_t> blocked(64);
  std::size_t count = 0;
  for (auto _ : state)
    for (std::size_t p = 0; p < 64; ++p) {
      s.rays->occluded(s.from[p], std::span<const dvec3>(s.to).subspan(64 * p, 64), blocked);
      count += blocked[0];
    }
  benchmark::DoNotOptimize(count);
  state.SetItemsProcessed(state.iterations() * 4096);
}
BENCHMARK(BM_ShadowRays_EmbreeOccluded8)->Unit(benchmark::kMicrosecond);

// Our rays against the first N shaft candidates (the cost grows with N; Embree's
// against the whole scene does not): where the two cross over.
void BM_ShadowRays_OwnAgainstNCandidates(benchmark::State& state) {
  const ClutterScene& s = clutter();
  const auto count =
      std::min<std::size_t>(static_cast<std::size_t>(state.range(0)), s.candidates.size());
  const std::span<const Triangle> candidates(s.candidates.data(), count);
  EmitterSamples samples;
  samples.weights.assign(64, 1.0);
  double sum = 0.0;
  for (auto _ : state)
    for (std::size_t p = 0; p < 64; ++p) {
      samples.points.assign(s.to.begin() + static_cast<std::ptrdiff_t>(64 * p),
                            s.to.begin() + static_cast<std::ptrdiff_t>(64 * p + 64));
      sum += visible_fraction(candidates, s.from[p], samples);
    }
  benchmark::DoNotOptimize(sum);
  state.SetItemsProcessed(state.iterations() * 4096);
  state.counters["candidates"] = static_cast<double>(count);
}
BENCHMARK(BM_ShadowRays_OwnAgainstNCandidates)
    ->Arg(1)
    ->Arg(4)
    ->Arg(16)
    ->Arg(64)
    ->Unit(benchmark::kMicrosecond);

void BM_ShaftCulling_Bvh(benchmark::State& state) {
  const ClutterScene& s = clutter();
  for (auto _ : state) {
    const ShaftCulling c = cull_shaft(s.scene, s.receiver, kNoFace, s.emitter, kNoFace);
    benchmark::DoNotOptimize(c.candidates.data());
  }
}
BENCHMARK(BM_ShaftCulling_Bvh)->Unit(benchmark::kMicrosecond);

void BM_ShaftCulling_BruteForce(benchmark::State& state) {
  const ClutterScene& s = clutter();
  for (auto _ : state) {
    const ShaftCulling c = cull_shaft_brute_force(s.scene, s.receiver, kNoFace, s.emitter, kNoFace);
    benchmark::DoNotOptimize(c.candidates.data());
  }
}
BENCHMARK(BM_ShaftCulling_BruteForce)->Unit(benchmark::kMicrosecond);

// BVH builds, ours (binned SAH, one thread) and Embree's rtcBuildBVH, on random
// scenes of 5k and 200k triangles; then shaft queries through each tree.
std::vector<Triangle> random_triangles(std::size_t count) {
  std::mt19937_64 rng(count);
  std::vector<Triangle> triangles(count);
  const double extent = 5.0 * std::cbrt(static_cast<double>(count) / 5000.0);
  for (Triangle& t : triangles) {
    const dvec3 c = uniform_in(rng, dvec3(-extent), dvec3(extent));
    for (dvec3& v : t.v) v = c + uniform_in(rng, dvec3(-0.1), dvec3(0.1));
  }
  return triangles;
}

void BM_BuildBvh_Own(benchmark::State& state) {
  const std::vector<Triangle> triangles =
      random_triangles(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(build_scene_bvh(triangles).nodes.data());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_BuildBvh_Own)->Arg(5000)->Arg(200000)->Unit(benchmark::kMillisecond);

void BM_BuildBvh_Embree(benchmark::State& state) {
  const std::vector<Triangle> triangles =
      random_triangles(static_cast<std::size_t>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(build_scene_bvh_embree(triangles).nodes.data());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_BuildBvh_Embree)->Arg(5000)->Arg(200000)->Unit(benchmark::kMillisecond);

// Shaft queries between random element pairs 1 to 3 apart, through a tree built
// by us (arg 0) or by Embree (arg 1), 200k triangles.
void BM_ShaftCulling_Tree(benchmark::State& state) {
  static OccluderScene own = make_occluder_scene(random_triangles(200000));
  static OccluderScene embree = [] {
    OccluderScene s = own;
    s.bvh = build_scene_bvh_embree(s.triangles);
    return s;
  }();
  const OccluderScene& scene = state.range(0) == 0 ? own : embree;
  std::mt19937_64 rng(5);
  std::vector<std::pair<Polygon, Polygon>> links;
  for (int i = 0; i < 256; ++i) {
    const dvec3 c = uniform_in(rng, dvec3(-20.0), dvec3(20.0));
    const dvec3 d = c + uniform_in(rng, dvec3(-3.0), dvec3(3.0));
    links.push_back({{c, c + dvec3(0.5, 0, 0), c + dvec3(0.5, 0.5, 0), c + dvec3(0, 0.5, 0)},
                     {d, d + dvec3(0, 0.5, 0), d + dvec3(0.5, 0.5, 0.1), d + dvec3(0.5, 0, 0.1)}});
  }
  std::size_t i = 0, candidates = 0;
  for (auto _ : state) {
    const ShaftCulling c = cull_shaft(scene, links[i].first, kNoFace, links[i].second, kNoFace);
    candidates += c.candidates.size();
    i = (i + 1) % links.size();
  }
  state.counters["candidates"] =
      static_cast<double>(candidates) / static_cast<double>(state.iterations());
  state.counters["nodes"] = static_cast<double>(scene.bvh.nodes.size());
}
BENCHMARK(BM_ShaftCulling_Tree)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Occluders in the pyramid from a receiver point to a unit emitter, overlapping.
struct OccluderConfigurations {
  Polygon emitter{{-0.5, -0.5, 2.0}, {-0.5, 0.5, 2.0}, {0.5, 0.5, 2.0}, {0.5, -0.5, 2.0}};
  std::vector<dvec3> points;
  std::vector<std::vector<Triangle>> occluders;  // per point

  OccluderConfigurations(int count, int configurations) {
    std::mt19937_64 rng(static_cast<std::uint64_t>(count));
    for (int i = 0; i < configurations; ++i) {
      const dvec3 r = uniform_in(rng, {-0.3, -0.3, 0.0}, {0.3, 0.3, 0.0});
      points.push_back(r);
      std::vector<Triangle> tris;
      // Size so that the occluders cover about half the emitter together.
      const double size = 0.35 / std::sqrt(static_cast<double>(count));
      for (int k = 0; k < count; ++k) {
        const dvec3 target = uniform_in(rng, {-0.5, -0.5, 2.0}, {0.5, 0.5, 2.0});
        const dvec3 c = r + uniform_in(rng, dvec3(0.3), dvec3(0.7)) * (target - r);
        Triangle t;
        for (dvec3& v : t.v) v = c + uniform_in(rng, dvec3(-size), dvec3(size));
        tris.push_back(t);
      }
      occluders.push_back(tris);
    }
  }
};

void BM_ExactVisiblePolygon(benchmark::State& state) {
  const int count = static_cast<int>(state.range(0));
  const OccluderConfigurations c(count, 64);
  const dvec3 n(0.0, 0.0, 1.0);
  std::size_t i = 0;
  double pieces = 0.0;
  for (std::size_t k = 0; k < c.points.size(); ++k)
    pieces += static_cast<double>(
        visible_polygon(c.points[k], n, c.emitter, c.occluders[k]).pieces.size());
  for (auto _ : state) {
    const FormFactorGradient fg =
        visible_form_factor_gradient(c.points[i], n, c.emitter, c.occluders[i]);
    benchmark::DoNotOptimize(fg.value);
    i = (i + 1) % c.points.size();
  }
  state.counters["occluders"] = count;
  state.counters["pieces"] = pieces / static_cast<double>(c.occluders.size());
}
BENCHMARK(BM_ExactVisiblePolygon)->Arg(1)->Arg(4)->Arg(16)->Arg(64)->Unit(benchmark::kMicrosecond);

// Closed meshes: N boxes (12 triangles each) in the pyramid, their quads as
// consecutive triangle pairs (arg 1 = 1, merged into quads) or interleaved
// (arg 1 = 0, subtracted triangle by triangle).
void BM_ExactVisibleBoxes(benchmark::State& state) {
  const int boxes = static_cast<int>(state.range(0));
  const bool consecutive = state.range(1) != 0;
  const Polygon emitter{{-0.5, -0.5, 2.0}, {-0.5, 0.5, 2.0}, {0.5, 0.5, 2.0}, {0.5, -0.5, 2.0}};
  std::mt19937_64 rng(static_cast<std::uint64_t>(boxes));
  std::vector<dvec3> points;
  std::vector<std::vector<Triangle>> occluders;
  for (int c = 0; c < 64; ++c) {
    const dvec3 r = uniform_in(rng, {-0.3, -0.3, 0.0}, {0.3, 0.3, 0.0});
    points.push_back(r);
    std::vector<Triangle> tris;
    const double size = 0.25 / std::sqrt(static_cast<double>(boxes));
    for (int b = 0; b < boxes; ++b) {
      const dvec3 target = uniform_in(rng, {-0.5, -0.5, 2.0}, {0.5, 0.5, 2.0});
      const dvec3 lo = r + uniform_in(rng, dvec3(0.3), dvec3(0.7)) * (target - r);
      const dvec3 hi = lo + uniform_in(rng, dvec3(0.5 * size), dvec3(size));
      const auto corner = [&](int i) {
        return dvec3(i & 1 ? hi.x : lo.x, i & 2 ? hi.y : lo.y, i & 4 ? hi.z : lo.z);
      };
      const int faces[6][4] = {{0, 1, 3, 2}, {4, 6, 7, 5}, {0, 4, 5, 1},
                               {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 5, 7, 3}};
      for (const auto& f : faces) {
        tris.push_back(Triangle{{corner(f[0]), corner(f[1]), corner(f[2])}});
        tris.push_back(Triangle{{corner(f[0]), corner(f[2]), corner(f[3])}});
      }
    }
    if (!consecutive) {
      std::vector<Triangle> apart;
      for (std::size_t k = 0; k < tris.size(); k += 2) apart.push_back(tris[k]);
      for (std::size_t k = 1; k < tris.size(); k += 2) apart.push_back(tris[k]);
      tris = apart;
    }
    occluders.push_back(tris);
  }
  const dvec3 n(0.0, 0.0, 1.0);
  double pieces = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k)
    pieces +=
        static_cast<double>(visible_polygon(points[k], n, emitter, occluders[k]).pieces.size());
  std::size_t i = 0;
  for (auto _ : state) {
    const FormFactorGradient fg = visible_form_factor_gradient(points[i], n, emitter, occluders[i]);
    benchmark::DoNotOptimize(fg.value);
    i = (i + 1) % points.size();
  }
  state.counters["triangles"] = 12 * boxes;
  state.counters["pieces"] = pieces / static_cast<double>(points.size());
}
BENCHMARK(BM_ExactVisibleBoxes)->ArgsProduct({{1, 4, 16}, {0, 1}})->Unit(benchmark::kMicrosecond);

// Sampled mode, 4 occluders: cost per evaluation (Embree rays; the scene is built
// once per configuration, outside the timing) and the mean error against the
// exact F relative to the unoccluded F, over 64 configurations.
void BM_SampledVisibility(benchmark::State& state) {
  const int rays = static_cast<int>(state.range(0));
  const OccluderConfigurations c(4, 64);
  const dvec3 n(0.0, 0.0, 1.0);
  std::vector<std::unique_ptr<RayScene>> scenes;
  double error = 0.0;
  SampledVisibilityOptions options;
  options.rays = rays;
  for (std::size_t k = 0; k < c.points.size(); ++k) {
    scenes.push_back(std::make_unique<RayScene>(c.occluders[k]));
    const double exact =
        visible_form_factor_gradient(c.points[k], n, c.emitter, c.occluders[k]).value;
    const double unoccluded = form_factor(c.points[k], n, c.emitter);
    options.seed = k;
    const double sampled =
        sampled_form_factor_gradient(c.points[k], n, c.emitter, *scenes[k], options).value;
    error += std::abs(sampled - exact) / unoccluded / static_cast<double>(c.points.size());
  }
  std::size_t i = 0;
  for (auto _ : state) {
    options.seed = i;
    const FormFactorGradient fg =
        sampled_form_factor_gradient(c.points[i], n, c.emitter, *scenes[i], options);
    benchmark::DoNotOptimize(fg.value);
    i = (i + 1) % c.points.size();
  }
  state.counters["rays"] = rays;
  state.counters["mean_rel_error"] = error;
}
BENCHMARK(BM_SampledVisibility)->RangeMultiplier(4)->Range(16, 4096)->Unit(benchmark::kMicrosecond);

// The exact mode on the same 4-occluder configurations, for comparison.
void BM_ExactVisibility4(benchmark::State& state) {
  const OccluderConfigurations c(4, 64);
  const dvec3 n(0.0, 0.0, 1.0);
  std::size_t i = 0;
  for (auto _ : state) {
    const FormFactorGradient fg =
        visible_form_factor_gradient(c.points[i], n, c.emitter, c.occluders[i]);
    benchmark::DoNotOptimize(fg.value);
    i = (i + 1) % c.points.size();
  }
  state.counters["mean_rel_error"] = 0.0;
}
BENCHMARK(BM_ExactVisibility4)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace radiosity

BENCHMARK_MAIN();
