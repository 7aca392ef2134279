// Shaft culling (Haines and Wallace 1994; Section 4.3): the candidate occluders
// of a link between a receiver element and an emitter element, found once per
// link. The shaft is the convex hull of the two elements; a triangle that does
// not reach into its interior cannot block any segment between them.
//
// The hull's planes are found exactly (every plane through three of the
// elements' corners that has all corners on one side), which is tighter than the
// box-based shaft of the original paper and cheap for the 6 to 8 corners of a
// link. Candidates come from the scene's BVH (scene_bvh.h), minus the two
// elements' own faces.
//
// Fast answers: `clear` when no candidate is left; `hidden` when the candidates
// lying in one plane (one face, or a wall made of many) separate the two
// elements and together cover the whole cross-section of the shaft on that
// plane, so that every segment between the elements crosses them.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "core/geometry/triangle.h"
#include "core/visibility/scene_bvh.h"
#include "radiosity/vec.h"

namespace radiosity {

// The scene as the visibility code sees it: triangles, the input face each
// belongs to (links exclude their own faces), and the BVH over them.
struct OccluderScene {
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> face;  // per triangle
  SceneBvh bvh;
};

// `face` may be empty (every triangle its own face).
OccluderScene make_occluder_scene(std::vector<Triangle> triangles,
                                  std::vector<std::uint32_t> face = {});

// A plane n . x = offset with unit n pointing out of the shaft.
struct ShaftPlane {
  dvec3 normal{0.0};
  double offset = 0.0;
  double distance(const dvec3& p) const { return glm::dot(normal, p) - offset; }
};

struct Shaft {
  std::vector<ShaftPlane> planes;
  Aabb box;
  double tolerance = 0.0;
  bool flat = false;  // the two elements are coplanar: no interior, nothing exchanged
};

Shaft make_shaft(std::span<const dvec3> receiver, std::span<const dvec3> emitter);

// True when the triangle reaches into the shaft's interior (conservative: it may
// still miss it near the hull's edges).
bool shaft_overlaps(const Shaft& shaft, const Triangle& t);

enum class ShaftVisibility { clear, partial, hidden };

struct ShaftCulling {
  ShaftVisibility visibility = ShaftVisibility::clear;
  std::vector<std::uint32_t> candidates;  // triangle indices into the scene
  bool truncated = false;                 // more than the limit: `candidates` holds only some
};

// With a `limit`, stops once more candidates than that are found (for
// shadow rays, which need no list): `hidden` is then still proved by the ones
// found, never `clear`.
ShaftCulling cull_shaft(const OccluderScene& scene, std::span<const dvec3> receiver,
                        std::uint32_t receiver_face, std::span<const dvec3> emitter,
                        std::uint32_t emitter_face,
                        std::size_t limit = std::numeric_limits<std::size_t>::max());

// The same without the BVH, every triangle tested: the reference for tests and
// benchmarks.
ShaftCulling cull_shaft_brute_force(const OccluderScene& scene, std::span<const dvec3> receiver,
                                    std::uint32_t receiver_face, std::span<const dvec3> emitter,
                                    std::uint32_t emitter_face);

}  // namespace radiosity
