// Shadow rays through Embree 3: an Embree scene over the scene's triangles, with
// a per-query filter that ignores the faces of the link being evaluated (the
// receiver's and the emitter's own faces must never shadow the link).
//
// Embree stores vertices in single precision; segments are shortened by a
// relative 1e-5 at both ends so a ray that starts or ends on a face near the
// link's own faces does not hit them through rounding.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/triangle.h"
#include "radiosity/vec.h"

// Embree's handles, declared as Embree declares them, so that this header
// does not bring Embree to every file that traces rays.
struct RTCDeviceTy;
struct RTCSceneTy;

namespace radiosity {

class RayScene {
 public:
  // `face` as in OccluderScene: may be empty (every triangle its own face).
  explicit RayScene(std::span<const Triangle> triangles, std::span<const std::uint32_t> face = {});
  ~RayScene();
  RayScene(const RayScene&) = delete;
  RayScene& operator=(const RayScene&) = delete;

  // Is the open segment from `from` to `to` blocked by a triangle whose face is
  // neither `skip_a` nor `skip_b`? (rtcOccluded1)
  bool occluded(const dvec3& from, const dvec3& to, std::uint32_t skip_a = kNoFace,
                std::uint32_t skip_b = kNoFace) const;

  // The same for segments from one point to many (packets of 8, rtcOccluded8,
  // where the build supports them; else one at a time). Writes 1 for blocked.
  void occluded(const dvec3& from, std::span<const dvec3> to, std::span<std::uint8_t> blocked,
                std::uint32_t skip_a = kNoFace, std::uint32_t skip_b = kNoFace) const;

  // The face of the nearest triangle on the segment from `from` to `to`, other
  // than those of face `skip`, and where along it (0 to 1); kNoFace if none.
  // (rtcIntersect1: the ray pass follows light to the surface it comes from.)
  std::uint32_t first_hit(const dvec3& from, const dvec3& to, std::uint32_t skip,
                          float& along) const;

  std::size_t size() const { return face_.size(); }

 private:
  RTCDeviceTy* device_ = nullptr;
  RTCSceneTy* scene_ = nullptr;
  std::vector<std::uint32_t> face_;
  bool packets8_ = false;
};

}  // namespace radiosity
