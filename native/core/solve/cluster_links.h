// Links between clusters (cluster_tree.h): how light crosses a large scene
// without a link for every pair of patches. Initial linking walks pairs of
// clusters from the root: a pair that faces away is dropped whole; a pair far
// apart (centres more than `separation` times the sum of their radii) whose
// sides all face each other along the line between their centres exchanges
// light through one cluster link; other pairs are split, down to pairs of
// top-level elements, which become ordinary links (exact form factors,
// refined by the oracle). A cluster link ends on one side and starts from a
// cluster of sides.
//
// Across a cluster link the direction w and distance d between the receiving
// side's centre and the emitter cluster's area centroid stand for those from
// each of the emitter's sides, so the form factor from side q of the emitter
// to a point of the receiving side p is A_q (n_q . w) (-n_p . w) / (pi d^2).
// Summed over the emitter this needs only its power vector
// P = sum of L_q A_q n_q (linear because every side of a linked cluster faces
// the receiver); measured from the centroid, the error of 1/d^2 over the
// emitter's extent cancels to first order where its radiance is uniform.
// Visibility is the fraction of shadow rays, between random points of the
// emitter's sides and of the receiving side, that pass; none: no link.
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <vector>

#include "core/hierarchy/cluster_tree.h"
#include "core/solve/link_transport.h"
#include "core/visibility/ray_scene.h"

namespace radiosity {

struct ClusterLink {
  std::int32_t receiver = kNone;  // cluster nodes
  std::int32_t emitter = kNone;
  std::array<float, 3> direction{};  // unit, emitter centroid to receiver centroid
  float coupling = 0.0f;             // visible fraction / (pi d^2)
};

struct InitialLinks {
  std::vector<ClusterLink> clusters;
  std::vector<Link> elements;  // candidate pairs of top-level elements, not yet evaluated
};

// The walk described above; `separation` > 1, `rays` shadow rays per cluster
// link. Returns early (incomplete) once `cancelled` (called from worker
// threads, so it must be thread-safe) says so; `progress`, if
// set, hears the fraction of the walk done (from the walking thread).
InitialLinks link_clusters(const ClusterTree& tree, const Hierarchy& hierarchy,
                           const RayScene& scene, double separation, int rays,
                           const std::function<bool()>& cancelled,
                           const std::function<void(double)>& progress = {});

// What every top-level element gathers through the cluster links, uniform
// over the element (far light): indexed by element id, zero for the others.
// The emitters' power vectors are summed up the tree once per call.
class ClusterGather {
 public:
  void operator()(const ClusterTree& tree, const std::vector<ClusterLink>& links,
                  const Hierarchy& hierarchy, const std::vector<Rgb>& radiance,
                  std::vector<Rgb>& gathered);
  std::size_t memory_bytes() const { return power_.capacity() * sizeof(ChannelVectors); }

 private:
  using ChannelVectors = std::array<dvec3, 3>;  // one vector per colour channel
  std::vector<ChannelVectors> power_;           // per cluster node
};

}  // namespace radiosity
