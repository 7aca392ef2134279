// Embree scene for shadow rays (see ray_scene.h).
#include "core/visibility/ray_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>
#include <string>

#include "core/visibility/embree_device.h"

namespace radiosity {
namespace {

// The query context carries the faces to ignore; the filter rejects hits on them.
struct FilterContext {
  RTCIntersectContext embree;  // first member: Embree passes a pointer to it back
  const std::uint32_t* face = nullptr;
  std::uint32_t skip_a = kNoFace, skip_b = kNoFace;
};

void skip_own_faces(const RTCFilterFunctionNArguments* args) {
  const auto* context = reinterpret_cast<const FilterContext*>(args->context);
  for (unsigned i = 0; i < args->N; ++i) {
    if (args->valid[i] == 0) continue;
    const std::uint32_t f = context->face[RTCHitN_primID(args->hit, args->N, i)];
    if (f == context->skip_a || f == context->skip_b) args->valid[i] = 0;
  }
}

// Segment parameters: the ray is from + t (to - from), t in [t_near, t_far].
// Single-precision vertices are off by about 6e-8 of the coordinates; keep that
// far from both ends.
float end_margin(const dvec3& from, const dvec3& to) {
  const double length = glm::length(to - from);
  const double magnitude = std::max({std::abs(from.x), std::abs(from.y), std::abs(from.z),
                                     std::abs(to.x), std::abs(to.y), std::abs(to.z)});
  return static_cast<float>(std::min(0.25, 1e-5 + 1e-6 * magnitude / length));
}

// A query context that skips the faces `skip_a` and `skip_b` (`face`: the
// triangles' faces). Embree copies nothing: it must outlive the query.
FilterContext filter_context(const std::uint32_t* face, std::uint32_t skip_a,
                             std::uint32_t skip_b) {
  FilterContext context;
  rtcInitIntersectContext(&context.embree);
  context.embree.filter = skip_own_faces;
  context.face = face;
  context.skip_a = skip_a;
  context.skip_b = skip_b;
  return context;
}

// The segment from `from` to `to` as an Embree ray, kept end_margin from both ends.
RTCRay segment_ray(const dvec3& from, const dvec3& to) {
  const float margin = end_margin(from, to);
  RTCRay ray;
  ray.org_x = static_cast<float>(from.x);
  ray.org_y = static_cast<float>(from.y);
  ray.org_z = static_cast<float>(from.z);
  ray.dir_x = static_cast<float>(to.x - from.x);
  ray.dir_y = static_cast<float>(to.y - from.y);
  ray.dir_z = static_cast<float>(to.z - from.z);
  ray.tnear = margin;
  ray.tfar = 1.0f - margin;
  ray.time = 0.0f;
  ray.mask = 0xFFFFFFFFu;
  ray.id = 0;
  ray.flags = 0;
  return ray;
}

}  // namespace

// One Embree device for the process: scenes are made per solve (or per Python
// call), devices would cost milliseconds each.
RTCDevice shared_embree_device() {
  static RTCDevice device = [] {
    RTCDevice d = rtcNewDevice("threads=0");
    if (!d) throw std::runtime_error("Embree: cannot create a device");
    // The link's own faces are skipped by a context filter; an Embree built
    // without filter functions ignores it silently and shadows every folded
    // face: refuse it.
    if (rtcGetDeviceProperty(d, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED) == 0) {
      rtcReleaseDevice(d);
      throw std::runtime_error(
          "Embree was built without filter functions (EMBREE_FILTER_FUNCTION=OFF); the solver "
          "needs them");
    }
    return d;
  }();
  return device;
}

RayScene::RayScene(std::span<const Triangle> triangles, std::span<const std::uint32_t> face)
    : face_(face.begin(), face.end()) {
  if (face_.size() != triangles.size()) {
    face_.resize(triangles.size());
    std::iota(face_.begin(), face_.end(), 0u);
  }
  device_ = shared_embree_device();
  rtcRetainDevice(device_);
  scene_ = rtcNewScene(device_);
  rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_CONTEXT_FILTER_FUNCTION);
  rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_HIGH);
  if (!triangles.empty()) {
    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vertices = static_cast<float*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                3 * sizeof(float), 3 * triangles.size()));
    auto* indices = static_cast<unsigned*>(
        rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(unsigned), triangles.size()));
    if (!vertices || !indices) {
      rtcReleaseGeometry(geometry);
      rtcReleaseScene(scene_);
      rtcReleaseDevice(device_);
      throw std::bad_alloc();
    }
    for (std::size_t t = 0; t < triangles.size(); ++t)
      for (int k = 0; k < 3; ++k) {
        for (int c = 0; c < 3; ++c)
          vertices[9 * t + 3 * k + c] = static_cast<float>(triangles[t].v[k][c]);
        indices[3 * t + k] = static_cast<unsigned>(3 * t + k);
      }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
  }
  rtcCommitScene(scene_);
  const RTCError error = rtcGetDeviceError(device_);
  if (error != RTC_ERROR_NONE) {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
    throw std::runtime_error("Embree: scene build failed (error " + std::to_string(error) + ")");
  }
  packets8_ = rtcGetDeviceProperty(device_, RTC_DEVICE_PROPERTY_NATIVE_RAY8_SUPPORTED) != 0;
}

RayScene::~RayScene() {
  rtcReleaseScene(scene_);
  rtcReleaseDevice(device_);
}

bool RayScene::occluded(const dvec3& from, const dvec3& to, std::uint32_t skip_a,
                        std::uint32_t skip_b) const {
  if (face_.empty() || from == to) return false;
  FilterContext context = filter_context(face_.data(), skip_a, skip_b);
  RTCRay ray = segment_ray(from, to);
  rtcOccluded1(scene_, &context.embree, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to -inf on a hit
}

std::uint32_t RayScene::first_hit(const dvec3& from, const dvec3& to, std::uint32_t skip,
                                  float& along) const {
  along = 1.0f;
  if (face_.empty() || from == to) return kNoFace;
  FilterContext context = filter_context(face_.data(), skip, kNoFace);
  RTCRayHit query;
  query.ray = segment_ray(from, to);
  const RTCRay& ray = query.ray;
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(scene_, &context.embree, &query);
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) return kNoFace;
  along = ray.tfar;
  return face_[query.hit.primID];
}

void RayScene::occluded(const dvec3& from, std::span<const dvec3> to,
                        std::span<std::uint8_t> blocked, std::uint32_t skip_a,
                        std::uint32_t skip_b) const {
  const std::size_t count = std::min(to.size(), blocked.size());
  if (face_.empty()) {
    std::fill(blocked.begin(), blocked.begin() + static_cast<std::ptrdiff_t>(count), 0);
    return;
  }
  if (!packets8_) {
    for (std::size_t i = 0; i < count; ++i) blocked[i] = occluded(from, to[i], skip_a, skip_b);
    return;
  }
  FilterContext context = filter_context(face_.data(), skip_a, skip_b);
  // Coherent rays from one point: the packet shares its origin.
  alignas(32) RTCRay8 packet;
  alignas(32) int valid[8];
  for (std::size_t base = 0; base < count; base += 8) {
    for (int k = 0; k < 8; ++k) {
      const std::size_t i = base + static_cast<std::size_t>(k);
      valid[k] = (i < count && to[i] != from) ? -1 : 0;
      const dvec3 target = i < count ? to[i] : from;
      const float margin = valid[k] ? end_margin(from, target) : 0.0f;
      packet.org_x[k] = static_cast<float>(from.x);
      packet.org_y[k] = static_cast<float>(from.y);
      packet.org_z[k] = static_cast<float>(from.z);
      packet.dir_x[k] = static_cast<float>(target.x - from.x);
      packet.dir_y[k] = static_cast<float>(target.y - from.y);
      packet.dir_z[k] = static_cast<float>(target.z - from.z);
      packet.tnear[k] = margin;
      packet.tfar[k] = 1.0f - margin;
      packet.time[k] = 0.0f;
      packet.mask[k] = 0xFFFFFFFFu;
      packet.id[k] = static_cast<unsigned>(k);
      packet.flags[k] = 0;
    }
    rtcOccluded8(valid, scene_, &context.embree, &packet);
    for (int k = 0; k < 8; ++k) {
      const std::size_t i = base + static_cast<std::size_t>(k);
      if (i < count) blocked[i] = valid[k] != 0 && packet.tfar[k] < 0.0f;
    }
  }
}

}  // namespace radiosity
