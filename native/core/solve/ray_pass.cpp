#include "core/solve/ray_pass.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>
#include <span>

#include "core/geometry/random.h"
#include "core/solve/direct_light.h"
#include "core/visibility/ray_scene.h"

namespace radiosity {
namespace {

constexpr double kTolerance = 1e-4;  // relative change of the total radiance
constexpr int kMaxIterations = 1000;
// How far toward the element's centre an escaped ray is tried again before
// the element is taken to see an opening (RayPass::escaped).
constexpr double kInset = 0.01;
// The share of a side's rays that must bring light (an emitter's, a light's
// or the sky's, or by meeting a side light reaches), and at least two, before
// light is taken to reach it (RayPass::unlit). A ray or two is what a crack between two
// triangles lets through (Embree intersects in float32 and is not
// watertight): of the 442,000 rays inside a closed UV sphere, ten sides got
// one and one side two.
constexpr double kShareThatBringsLight = 0.01;

// Every patch, the lights' too (a ray that meets a lamp takes its emission),
// tagged with its patch index.
RayScene patch_rays(const Scene& scene) {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> patch;
  triangles.reserve(2 * scene.patches.size());
  patch.reserve(2 * scene.patches.size());
  for (std::uint32_t p = 0; p < scene.patches.size(); ++p) {
    const Patch& q = scene.patches[p];
    triangles.push_back({{q.corners[0], q.corners[1], q.corners[2]}});
    patch.push_back(p);
    if (q.corner_count == 4) {
      triangles.push_back({{q.corners[0], q.corners[2], q.corners[3]}});
      patch.push_back(p);
    }
  }
  return RayScene(triangles, patch);
}

// A uniform point of a convex triangle or quad (split along its 0-2 diagonal).
dvec3 point_on(const dvec3* c, int corner_count, SplitMix64& random) {
  int second = 1;
  if (corner_count == 4) {
    const double a = glm::length(glm::cross(c[1] - c[0], c[2] - c[0]));
    const double b = glm::length(glm::cross(c[2] - c[0], c[3] - c[0]));
    if (random.uniform() * (a + b) >= a) second = 2;
  }
  const double r = std::sqrt(random.uniform()), s = random.uniform();
  return c[0] + r * (1.0 - s) * (c[second] - c[0]) + r * s * (c[second + 1] - c[0]);
}

// Cosine-weighted direction about `n`, stratified: ray k of `count` in its own
// cell of a sqrt(count) x sqrt(count) grid (jittered).
dvec3 cosine_direction(const dvec3& n, int k, int count, SplitMix64& random) {
  const int side = std::max(1, static_cast<int>(std::sqrt(static_cast<double>(count))));
  const int cell = k % (side * side);
  const double u = (cell % side + random.uniform()) / side;
  const double v = (cell / side + random.uniform()) / side;
  const dvec3 helper = std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t = glm::normalize(glm::cross(helper, n));
  const dvec3 b = glm::cross(n, t);
  const double r = std::sqrt(u), phi = 2.0 * std::numbers::pi * v;
  return r * std::cos(phi) * t + r * std::sin(phi) * b + std::sqrt(std::max(0.0, 1.0 - u)) * n;
}

}  // namespace

int ray_pass_rays(std::size_t reflecting) {
  const double share = 1.0e6 / static_cast<double>(std::max<std::size_t>(reflecting, 1));
  return std::clamp(static_cast<int>(share) / 16 * 16, 32, 2048);
}

namespace {

// The emitting top-level elements, drawn in proportion to their luminous power.
struct Emitters {
  std::vector<std::int32_t> element;
  std::vector<double> cumulative;  // of luminance(L_e) x area
  double total = 0.0;

  Emitters(const Hierarchy& h, std::span<const std::int32_t> roots) {
    for (std::int32_t id : roots) {
      const Element& e = h.element(id);
      const double power = luminance(h.emission(e)) * e.area;
      if (!(power > 0.0)) continue;
      total += power;
      element.push_back(id);
      cumulative.push_back(total);
    }
  }
  std::int32_t draw(double u) const {
    const auto at = std::upper_bound(cumulative.begin(), cumulative.end(), u * total);
    return element[static_cast<std::size_t>(
        std::min<std::ptrdiff_t>(at - cumulative.begin(), std::ssize(element) - 1))];
  }
  // Density of a drawn point per unit area of element `e`.
  double area_density(const Hierarchy& h, const Element& e) const {
    return luminance(h.emission(e)) / total;
  }
};

// Both ways of finding an emitter (a point drawn on it, a cosine ray that meets
// it) are weighted by the power heuristic (Veach 1997): the point near an
// emitter's edge, where 1 / d^2 grows without bound, the ray elsewhere.
double power_heuristic(double mine, double other) {
  return mine * mine / (mine * mine + other * other);
}

// Direct light of a point, spot or sun light at x (normal n), with one
// shadow ray: a point or spot as a point at its centre, the sun as a
// direction. The sky comes through the cosine rays that leave the scene.
Rgb light_at(const Light& light, const dvec3& x, const dvec3& n, std::uint32_t surface,
             const RayScene& occluders, double far) {
  if (light.kind == LightKind::Sun) {
    const dvec3 towards = -glm::normalize(light.direction);
    const double c = glm::dot(n, towards);
    if (!(c > 0.0) || occluders.occluded(x, x + far * towards, surface)) return Rgb(0.0);
    return light.colour * c;
  }
  if (light.kind == LightKind::Sky) return Rgb(0.0);
  const dvec3 d = light.position - x;
  const double d2 = glm::dot(d, d), nd = glm::dot(n, d);
  if (!(d2 > 0.0 && nd > 0.0)) return Rgb(0.0);
  const double spot =
      spot_factor(light, -glm::dot(glm::normalize(light.direction), d) / std::sqrt(d2)).value;
  if (!(spot > 0.0) || occluders.occluded(x, light.position, surface)) return Rgb(0.0);
  return light.colour * (spot * nd / (d2 * std::sqrt(d2)));
}

// RayPass::unlit: light spreads from the sides it starts at to every side
// with enough rays (kShareThatBringsLight) that met sides it reached (a breadth-first
// walk over the rays reversed).
std::vector<std::uint8_t> sides_no_light_reaches(const Hierarchy& hierarchy,
                                                 std::span<const std::int32_t> root_element,
                                                 std::span<const std::uint32_t> lighting_rays,
                                                 std::span<const std::int32_t> met,
                                                 std::size_t rays) {
  const std::size_t count = lighting_rays.size();
  // The rays that met element m, by their element: by_met[first[m], first[m + 1]).
  std::vector<std::size_t> first(count + 1, 0);
  for (std::int32_t m : met)
    if (m != kNone) ++first[static_cast<std::size_t>(m) + 1];
  for (std::size_t m = 0; m < count; ++m) first[m + 1] += first[m];
  std::vector<std::int32_t> by_met(first[count]);
  std::vector<std::size_t> fill(first.begin(), first.end() - 1);
  for (std::size_t r = 0; r < met.size(); ++r)
    if (met[r] != kNone)
      by_met[fill[static_cast<std::size_t>(met[r])]++] = static_cast<std::int32_t>(r / rays);

  const auto enough = std::max<std::uint32_t>(
      2, static_cast<std::uint32_t>(std::ceil(kShareThatBringsLight * static_cast<double>(rays))));
  std::vector<std::uint32_t> bringing(lighting_rays.begin(), lighting_rays.end());
  std::vector<std::uint8_t> reached(count, 0);
  std::vector<std::int32_t> queue;
  for (std::int32_t id : root_element) {
    const auto i = static_cast<std::size_t>(id);
    if (luminance(hierarchy.emission(hierarchy.element(id))) > 0.0 || bringing[i] >= enough) {
      reached[i] = 1;
      queue.push_back(id);
    }
  }
  while (!queue.empty()) {
    const auto m = static_cast<std::size_t>(queue.back());
    queue.pop_back();
    for (std::size_t r = first[m]; r < first[m + 1]; ++r) {
      const auto i = static_cast<std::size_t>(by_met[r]);
      if (!reached[i] && ++bringing[i] >= enough) {
        reached[i] = 1;
        queue.push_back(by_met[r]);
      }
    }
  }
  std::vector<std::uint8_t> unlit(count, 0);
  for (std::int32_t id : root_element) {
    const auto i = static_cast<std::size_t>(id);
    unlit[i] = !reached[i] && hierarchy.reflects(hierarchy.element(id));
  }
  return unlit;
}

}  // namespace

RayPass ray_pass(const Hierarchy& hierarchy, const RayScene& occluders,
                 const std::function<bool()>& cancelled) {
  const Scene& scene = hierarchy.scene();
  const std::size_t roots = hierarchy.root_count();
  // Top-level element ids: the roots are the first elements.
  std::vector<std::int32_t> root_element;
  for (std::size_t r = 0; r < roots; ++r) {
    const std::int32_t e =
        hierarchy.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (e != kNone) root_element.push_back(e);
  }
  const std::size_t count =
      root_element.empty()
          ? 0
          : static_cast<std::size_t>(*std::max_element(root_element.begin(), root_element.end())) +
                1;
  std::size_t reflecting = 0;
  for (std::int32_t e : root_element) reflecting += hierarchy.reflects(hierarchy.element(e));
  Rgb sky(0.0);
  for (const Light& light : scene.lights)
    if (light.kind == LightKind::Sky) sky += light.colour;

  RayPass pass;
  pass.rays = ray_pass_rays(reflecting);
  pass.gathered.assign(count, Rgb(0.0));
  pass.escaped.assign(count, 0.0f);
  const auto rays = static_cast<std::size_t>(pass.rays);
  // Per element: the direct light of emitters, lights and sky (fixed), and
  // the top-level element each cosine ray meets (kNone: the sky, or the back
  // of a one-sided face).
  std::vector<Rgb> fixed(count, Rgb(0.0));
  std::vector<std::int32_t> met(count * rays, kNone);
  std::vector<std::uint32_t> lighting_rays(count, 0);  // rays that brought direct light
  const Emitters emitters(hierarchy, root_element);
  const RayScene tracer = patch_rays(scene);
  const double reach = 2.0 * std::max(scene.diameter, 1e-300);
  // Does the ray from `from` along `w` end on a side that has an element?
  const auto meets_element = [&](const dvec3& from, const dvec3& w, std::uint32_t skip) {
    float along = 1.0f;
    const std::uint32_t p = tracer.first_hit(from, from + reach * w, skip, along);
    return p != kNoFace &&
           hierarchy.root(p, glm::dot(w, scene.patches[p].normal) < 0.0 ? 0 : 1) != kNone;
  };
  // A lamp that casts no shadow (Blender's lights) hides nothing behind its
  // back: the ray goes on past it.
  const auto through_lamp_meets_element = [&](const dvec3& from, const dvec3& w,
                                              std::uint32_t lamp) {
    return !scene.patches[lamp].occludes && meets_element(from, w, lamp);
  };
  std::atomic<bool> stop{false};
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, root_element.size(), 16), [&](const auto& range) {
        if (stop || (cancelled && cancelled())) {
          stop = true;
          return;
        }
        for (std::size_t i = range.begin(); i != range.end(); ++i) {
          const std::int32_t id = root_element[i];
          const auto at = static_cast<std::size_t>(id);
          const Element& e = hierarchy.element(id);
          if (!hierarchy.reflects(e)) continue;
          dvec3 corner[4];
          hierarchy.corners(e, corner);
          const dvec3 n = hierarchy.normal(e);
          dvec3 centre(0.0);
          for (int c = 0; c < e.corner_count; ++c)
            centre += corner[c] / static_cast<double>(e.corner_count);
          const std::uint32_t surface = hierarchy.patch_of(e).surface;
          SplitMix64 random{0x5EEDull * static_cast<std::uint64_t>(id + 1)};
          Rgb direct(0.0);
          std::size_t escaped = 0;
          std::uint32_t lighting = 0;  // rays that brought direct light
          for (std::size_t k = 0; k < rays; ++k) {
            const Rgb direct_before = direct;
            const dvec3 x = point_on(corner, e.corner_count, random);
            for (const Light& light : scene.lights)
              direct += light_at(light, x, n, surface, occluders, reach);
            if (!emitters.element.empty()) {  // a point drawn on an emitter
              const Element& q = hierarchy.element(emitters.draw(random.uniform()));
              dvec3 q_corner[4];
              hierarchy.corners(q, q_corner);
              const dvec3 d = point_on(q_corner, q.corner_count, random) - x;
              const double d2 = glm::dot(d, d), length = std::sqrt(d2);
              const double cos_x = glm::dot(n, d) / length,
                           cos_y = -glm::dot(hierarchy.normal(q), d) / length;
              if (cos_x > 0.0 && cos_y > 0.0 && d2 > 0.0 &&
                  !occluders.occluded(x, x + d, surface, hierarchy.patch_of(q).surface)) {
                // Densities per solid angle: the point's, and a cosine ray's.
                const double by_point = emitters.area_density(hierarchy, q) * d2 / cos_y;
                const double by_ray = cos_x / std::numbers::pi;
                direct +=
                    hierarchy.emission(q) * (by_ray / by_point * power_heuristic(by_point, by_ray));
              }
            }
            const dvec3 w = cosine_direction(n, static_cast<int>(k), pass.rays, random);
            float along = 1.0f;
            const std::uint32_t p = tracer.first_hit(x, x + reach * w, e.patch, along);
            if (p == kNoFace) {
              direct += sky;
              // A ray from within the segments' margin of a surface the element
              // meets at an edge (a ceiling's point beside a wall) slips past
              // it: an opening is where a ray leaves from inside the element too.
              const dvec3 inside = x + kInset * (centre - x);
              escaped += meets_element(inside, w, e.patch) ? 0 : 1;
            } else {
              const dvec3 normal_p = scene.patches[p].normal;
              const int side = glm::dot(w, normal_p) < 0.0 ? 0 : 1;
              const std::int32_t hit = hierarchy.root(p, side);
              met[at * rays + k] = hit;
              escaped += hit != kNone || through_lamp_meets_element(x, w, p) ? 0 : 1;
              if (hit != kNone && !emitters.element.empty() &&
                  luminance(hierarchy.emission(hierarchy.element(hit))) > 0.0) {
                const Element& q = hierarchy.element(hit);
                const double d = along * reach, cos_y = std::abs(glm::dot(w, normal_p));
                const double by_point =
                    emitters.area_density(hierarchy, q) * d * d / std::max(cos_y, 1e-300);
                const double by_ray = glm::dot(n, w) / std::numbers::pi;
                direct += hierarchy.emission(q) * power_heuristic(by_ray, by_point);
              }
            }
            if (direct != direct_before) ++lighting;
          }
          lighting_rays[at] = lighting;
          fixed[at] = direct / static_cast<double>(rays);
          pass.escaped[at] =
              static_cast<float>(static_cast<double>(escaped) / static_cast<double>(rays));
        }
      });
  if (stop) return pass;
  pass.unlit = sides_no_light_reaches(hierarchy, root_element, lighting_rays, met, rays);

  // Jacobi on the reflected radiance R = rho (H_direct + mean of R over the rays).
  std::vector<Rgb> reflected(count, Rgb(0.0)), next(count, Rgb(0.0));
  for (std::int32_t id : root_element) {
    const auto i = static_cast<std::size_t>(id);
    reflected[i] = hierarchy.reflectance(hierarchy.element(id)) * fixed[i];
  }
  for (pass.iterations = 1; pass.iterations <= kMaxIterations; ++pass.iterations) {
    if (cancelled && cancelled()) return pass;
    const auto [change, total] = tbb::parallel_reduce(
        tbb::blocked_range<std::size_t>(0, root_element.size(), 256),
        std::pair<double, double>{0.0, 0.0},
        [&](const auto& range, std::pair<double, double> sum) {
          for (std::size_t j = range.begin(); j != range.end(); ++j) {
            const auto i = static_cast<std::size_t>(root_element[j]);
            const Element& e = hierarchy.element(root_element[j]);
            Rgb h(0.0);
            for (std::size_t k = 0; k < rays; ++k) {
              const std::int32_t m = met[i * rays + k];
              if (m != kNone) h += reflected[static_cast<std::size_t>(m)];
            }
            h = h / static_cast<double>(rays) + fixed[i];
            next[i] = hierarchy.reflectance(e) * h;
            pass.gathered[i] = h;
            sum.first += e.area * std::abs(luminance(next[i] - reflected[i]));
            sum.second += e.area * luminance(next[i]);
          }
          return sum;
        },
        [](auto a, auto b) {
          return std::pair{a.first + b.first, a.second + b.second};
        });
    reflected.swap(next);
    if (!(change > kTolerance * total)) break;
  }
  pass.met = std::move(met);
  pass.lighting_rays = std::move(lighting_rays);
  pass.complete = true;
  return pass;
}

}  // namespace radiosity
