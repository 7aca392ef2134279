#include "core/link_transport.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <vector>

#include "core/form_factor.h"
#include "core/sampled_visibility.h"
#include "core/visible_polygon.h"

namespace radiosity {
namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Some corner of `polygon` lies strictly in front of the plane (point, normal),
// by more than rounding relative to the sizes involved.
bool any_in_front(const dvec3* polygon, int count, const dvec3& point, const dvec3& normal,
                  double tolerance) {
  for (int k = 0; k < count; ++k) {
    if (glm::dot(normal, polygon[k] - point) > tolerance) return true;
  }
  return false;
}

double distance_to_segment(const dvec3& p, const dvec3& a, const dvec3& b) {
  const dvec3 ab = b - a;
  const double t = std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0);
  return glm::length(p - (a + t * ab));
}

// Distance from p to a planar convex polygon (counter-clockwise about its normal).
double distance_to_polygon(const dvec3& p, std::span<const dvec3> polygon) {
  const size_t k = polygon.size();
  const dvec3 normal = glm::normalize(glm::cross(polygon[1] - polygon[0], polygon[k - 1] - polygon[0]));
  bool inside = true;
  double edge = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < k; ++i) {
    const dvec3& a = polygon[i];
    const dvec3& b = polygon[(i + 1) % k];
    inside = inside && glm::dot(glm::cross(b - a, p - a), normal) >= 0.0;
    edge = std::min(edge, distance_to_segment(p, a, b));
  }
  return inside ? std::abs(glm::dot(p - polygon[0], normal)) : edge;
}

}  // namespace

SceneOccluders make_scene_occluders(const Scene& scene, VisibilityMode mode) {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> face;
  for (const Patch& p : scene.patches) {
    triangles.push_back({{p.corners[0], p.corners[1], p.corners[2]}});
    face.push_back(p.face);
    if (p.corner_count == 4) {
      triangles.push_back({{p.corners[0], p.corners[2], p.corners[3]}});
      face.push_back(p.face);
    }
  }
  SceneOccluders occluders;
  if (mode == VisibilityMode::Sampled) occluders.rays = std::make_unique<RayScene>(triangles, face);
  occluders.shafts = make_occluder_scene(std::move(triangles), std::move(face));
  return occluders;
}

bool elements_face_each_other(const Hierarchy& h, const Element& receiver, const Element& emitter) {
  dvec3 p[4], q[4];
  const int np = h.corners(receiver, p), nq = h.corners(emitter, q);
  const double tolerance = 1e-9 * (h.diameter(receiver) + h.diameter(emitter));
  return any_in_front(q, nq, p[0], h.normal(receiver), tolerance) &&
         any_in_front(p, np, q[0], h.normal(emitter), tolerance);
}

bool LinkEvaluator::evaluate(Link& link, LinkTimings& timings, CornerMemo* memo) const {
  const Element& receiver = hierarchy.element(link.receiver);
  const Element& emitter = hierarchy.element(link.emitter);
  link.form_factor.fill(0.0f);
  link.oracle = 0.0f;
  if (!elements_face_each_other(hierarchy, receiver, emitter)) return false;

  dvec3 receiver_corners[4], emitter_corners[4], x[kMaxSamples];
  const int nr = hierarchy.corners(receiver, receiver_corners);
  const int ne = hierarchy.corners(emitter, emitter_corners);
  const int ns = hierarchy.samples(receiver, x);
  const std::span<const dvec3> emitter_polygon(emitter_corners, static_cast<size_t>(ne));
  const dvec3 n = hierarchy.normal(receiver);

  auto start = Clock::now();
  const ShaftCulling culling = cull_shaft(
      occluders.shafts, std::span<const dvec3>(receiver_corners, static_cast<size_t>(nr)),
      hierarchy.patch_of(receiver).face, emitter_polygon, hierarchy.patch_of(emitter).face);
  timings.visibility += seconds_since(start);
  if (culling.visibility == ShaftVisibility::hidden) return false;

  start = Clock::now();
  thread_local std::vector<Triangle> candidates;
  candidates.clear();
  for (std::uint32_t t : culling.candidates) candidates.push_back(occluders.shafts.triangles[t]);
  const bool gradient = oracle_needs_gradient(oracle);
  double value[kMaxSamples];
  dvec3 grad[kMaxSamples];
  bool any = false;
  // A corner is shared with siblings only if it is far from the emitter: close
  // to it, the sample's millionth offset towards its own element's centre
  // matters (at a contact, how the light splits between two emitter children
  // depends on the direction of approach). At a tenth of the receiver's size
  // away, the offset changes F by about 1e-5 relative.
  if (memo) memo->use_emitter(link.emitter);
  const double near = 0.1 * hierarchy.diameter(receiver);
  for (int s = 0; s < ns; ++s) {
    const bool corner = s < receiver.corner_count;
    const std::uint32_t vertex = corner ? receiver.corner[static_cast<size_t>(s)] : 0u;
    const bool shared = memo && corner && distance_to_polygon(x[s], emitter_polygon) > near;
    const FormFactorGradient* known = shared ? memo->find(vertex) : nullptr;
    FormFactorGradient f;
    if (known) {
      f = *known;
      ++timings.samples_shared;
    } else if (culling.visibility == ShaftVisibility::clear) {
      ++timings.samples_clear;
      f = gradient ? form_factor_gradient(x[s], n, emitter_polygon)
                   : FormFactorGradient{form_factor(x[s], n, emitter_polygon), dvec3(0.0)};
    } else if (visibility == VisibilityMode::Exact) {
      ++timings.samples_occluded;
      f = visible_form_factor_gradient(x[s], n, emitter_polygon, candidates);
    } else {
      // Rays per sample vary their seed with the sample, so neighbours do not
      // share the same stratification pattern.
      // Few candidates: test them directly in double precision; many: let
      // Embree traverse the scene (the crossover measured near 35 candidates).
      ++timings.samples_occluded;
      const SampledVisibilityOptions options{rays, static_cast<std::uint64_t>(s)};
      f = candidates.size() > 32 && occluders.rays
              ? sampled_form_factor_gradient(x[s], n, emitter_polygon, *occluders.rays, options,
                                             hierarchy.patch_of(receiver).face,
                                             hierarchy.patch_of(emitter).face)
              : sampled_form_factor_gradient(x[s], n, emitter_polygon, candidates, options);
    }
    if (shared && !known) memo->add(vertex, f);
    value[s] = std::max(0.0, f.value);
    grad[s] = f.gradient;
    link.form_factor[static_cast<size_t>(s)] = static_cast<float>(value[s]);
    any |= value[s] > 0.0;
  }
  timings.form_factors += seconds_since(start);
  if (!any) return false;

  // A receiver sample touching the emitter's outline (elements meeting at an
  // edge or a corner) sees the contact itself: at a vertex a value that depends
  // on the direction of approach and an unbounded gradient (MATH.md s3), on an
  // edge a slope set by the emitter's width, steep for thin emitters (a table
  // leg on the floor). No element size makes the radiance linear there, so the
  // oracle judges the element by its other samples; the sample still gathers.
  start = Clock::now();
  const double contact = 1e-5 * hierarchy.diameter(receiver);
  dvec3 oracle_x[kMaxSamples], oracle_grad[kMaxSamples];
  double oracle_value[kMaxSamples];
  size_t used = 0;
  for (int s = 0; s < ns; ++s) {
    bool touching = false;
    for (int k = 0; k < ne; ++k) {
      touching |= distance_to_segment(x[s], emitter_corners[k], emitter_corners[(k + 1) % ne]) < contact;
    }
    if (touching) continue;
    oracle_x[used] = x[s];
    oracle_value[used] = value[s];
    oracle_grad[used] = grad[s];
    ++used;
  }
  LinkSamples samples{std::span<const dvec3>(oracle_x, used),
                      std::span<const double>(oracle_value, used),
                      std::span<const dvec3>(oracle_grad, used),
                      n,
                      receiver.area,
                      hierarchy.diameter(receiver)};
  link.oracle = used >= 2 ? static_cast<float>(oracle_geometry(oracle, samples) / geometric_scale) : 0.0f;
  timings.oracle += seconds_since(start);
  return true;
}

}  // namespace radiosity
