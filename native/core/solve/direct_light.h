// Direct light from the lights that are not surfaces (lights.h) at a receiver
// element's samples, with visibility (DESIGN s3): what the element gathers
// from each light before any bounce. The solver keeps one LightLink per leaf
// and light it reaches; refining an element replaces its light links by its
// children's, so direct light is always evaluated where it is gathered.
//
// Per light, at a sample x with normal n (H per unit of the light's colour):
//  - point or spot of radius 0: cos(theta) / d^2 (times the spot's
//    attenuation), visibility by one shadow ray: exact;
//  - point or spot of radius r: the form factor of the sphere (or a disk
//    facing x) divided by r^2: it looks from x like a disk spanning the same
//    cone, a 16-gon of equal area, so its visible part is the exact visible
//    polygon of visible_polygon.h (exact) or a ray-sampled fraction (sampled);
//  - sun: the form factor of its disk (angular diameter `angle`) over
//    sin^2(angle / 2), the disk placed beyond the scene along the sun's
//    direction from every sample, so it has no parallax; a sun of angle under
//    1e-4 radians is a direction with one shadow ray;
//  - sky: the form factor of the six faces of a box around the scene, which
//    every ray that leaves the scene reaches: for a uniform world, where the
//    box is does not matter, only which directions are open.
// Gradients with respect to x are exact for points and for the unoccluded
// sky; for spheres, discs and the sun they take the disk as fixed while x
// moves (what the visible polygon computes), a small error in the slope.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "core/hierarchy/hierarchy.h"
#include "core/solve/link_transport.h"
#include "core/solve/oracle.h"

namespace radiosity {

struct LightLink {
  std::int32_t receiver = kNone;
  std::uint32_t light = 0;                 // index into Scene::lights
  std::array<float, kMaxSamples> value{};  // H per unit colour, at each receiver sample
  float oracle = 0.0f;                     // geometric part of the oracle, as Link::oracle
  // Light the samples miss: the largest value on a 4 x 4 grid over the
  // receiver where it is more than twice the samples' largest (a spot's cone
  // or a sunlit patch falling between the corners and the centre of a wall),
  // else 0. The oracles judge only what the samples see; such a link splits
  // its receiver until they see it.
  float missed = 0.0f;
};

class DirectLight {
 public:
  DirectLight(const Hierarchy& hierarchy, const SceneOccluders& occluders,
              VisibilityMode visibility, int rays, Oracle oracle, double geometric_scale);

  // Fills the link's values and oracle for its receiver; false when no sample
  // receives any of the light.
  bool evaluate(LightLink& link) const;

  // The light each root side can receive from: every light, for every side
  // that reflects and faces it (lights are few; evaluation drops the rest).
  std::vector<LightLink> initial_links() const;

 private:
  struct Values {
    double value[kMaxSamples] = {};
    dvec3 gradient[kMaxSamples] = {};
  };
  void point_or_spot(const Light& light, const Element& receiver, Values& out) const;
  void sun(const Light& light, const Element& receiver, Values& out) const;
  void sky(const Element& receiver, Values& out) const;
  // The light's value, unoccluded but for one shadow ray to its centre, at
  // a 4 x 4 grid of points over the receiver: the largest (0 for the sky).
  double probe(const Light& light, const Element& receiver) const;
  // Visible form factor of `polygon` (seen from x, shadows from `candidates`
  // or, sampled, from rays) for each sample; `polygon_at` builds the polygon
  // seen from a sample and `shaft` bounds every such polygon.
  template <typename PolygonAt>
  void disk_light(const Element& receiver, const PolygonAt& polygon_at,
                  std::span<const dvec3> shaft, double scale, Values& out) const;

  const Hierarchy& hierarchy_;
  const SceneOccluders& occluders_;
  VisibilityMode visibility_;
  int rays_;
  Oracle oracle_;
  double geometric_scale_;
  double far_ = 1.0;                         // beyond the scene: where the sun's disk is put
  std::array<std::array<dvec3, 4>, 6> sky_;  // the box around the scene, faces looking in
};

// Spot attenuation at cosine c to the axis, and its derivative in c.
struct SpotFactor {
  double value, derivative;
};
SpotFactor spot_factor(const Light& light, double c);

}  // namespace radiosity
