// Links between clusters (cluster_tree.h): how light crosses a large scene,
// and within a dense object, without a link for every pair of faces (Smits,
// Arvo and Greenberg 1994; Sillion 1995; Willmott, Heckbert and Garland 1999).
//
// The walk takes pairs of clusters from the root: a pair that faces away is
// dropped whole; a pair whose sides all face each other along the line
// between their centres becomes one cluster link when the cluster criterion
// accepts it (below); other pairs are split, the larger cluster first, down
// to pairs of top-level elements, which become ordinary links (exact form
// factors, refined by the oracle). Both ends of a cluster link may be
// clusters.
//
// What a cluster link carries. With r = x - y from the emitter cluster's area
// centroid y to a receiving point x, d = |r|, the form factor from a side q
// of the emitter to x (normal n) is A_q (n_q . r)(-n . r) / (pi d^4), so the
// emitter acts through its power vector P = sum of L_q A_q n_q (linear,
// because every side of a linked cluster faces the receiver; taken from the
// centroid, the error of 1/d^2 over the emitter's extent cancels to first
// order where its radiance is uniform). The receiver gathers
//   H(x) = V (P . r)(-n . r) / (pi d^4),
// V the fraction of shadow rays between random points of the two clusters
// that pass (none: no link), times the second-order correction for the
// clusters' extent (extent_correction, below: a point kernel is convex at a
// distance, so its value at the centres misses light between clusters
// twice their radii apart by up to a tenth). H is linear in n, so a receiving cluster keeps,
// per colour channel, the vector S with H = n . S at its centroid c, and the
// matrix G of H's first-order change, H(c + delta) = n . S + n^T G delta
// (d H / d x at fixed n, summed over its links: also linear). Pushed down the
// cluster tree (S_child = S + G (c_child - c), G_child = G), each side reads
// H at its own samples through its own normal: a receiving cluster no longer
// gives every side the light of its centre (off by 2 r / d), and the shading
// across a dense mesh that only clusters light is smooth to first order.
//
// The cluster criterion. A pair is accepted when its clusters are further
// apart than `separation` times the sum of their radii (far light is smooth at
// that distance), or, from twice that sum on, when the light the link could
// carry, times the relative error of the point approximation, is below the
// threshold: rho_X A_X min(L_peak, Phi_Y / (pi g^2)) min(1, 2 (r_X + r_Y) / d),
// over the adaptation radiance times the total area (the standard oracle's
// scale: a link's error in power), with g = d - r_X - r_Y the gap and Phi_Y
// the luminance flux of the emitter cluster. Small clusters that see each
// other from close by (the faces of a subdivided head across its eyes) carry
// little light, and link as clusters; a lamp over a table does not.
//
// An emitter cluster whose sides do not all face the receiver (the dents of
// a sculpted mesh, a curved object seen from beside) has no power vector that
// holds: a side facing away would send negative light. Where the whole light
// of the pair is below the threshold it links as an isotropic cluster
// (Sillion 1995): its area-average radiance from the area it shows towards
// the receiver, A_Y(w) L_Y / A_Y in place of P . w. A receiving cluster whose
// sides do not all face the emitter takes such faint light as light from one
// direction in a spherical-harmonic irradiance of order 2 (Ramamoorthi and
// Hanrahan 2001): nine numbers per channel, summed over its links and down
// the tree, from which each side reads the light on its own normal (the
// clamped cosine of one direction to within a tenth of its peak: a side
// facing away gets 6 % of what one facing it gets).
#pragma once

#include <array>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include "core/hierarchy/cluster_tree.h"
#include "core/solve/gather.h"
#include "core/solve/link_transport.h"
#include "core/visibility/ray_scene.h"

namespace radiosity {

struct ClusterLink {
  std::int32_t receiver = kNone;  // cluster nodes
  std::int32_t emitter = kNone;
  float visibility = 0.0f;  // fraction of the shadow rays between the clusters that pass
  float extent = 1.0f;      // second-order correction for the clusters' extent (above)
  // From an isotropic emitter (its sides do not all face the receiver): the
  // share of its area it shows towards the receiver, A_Y(w) / A_Y.
  float shown = 0.0f;
  // To a spherical receiver (its sides do not all face the emitter): the
  // share of its area it shows towards the emitter, A_X(-w) / A_X.
  float seen = 0.0f;
  std::uint8_t isotropic = 0;
  std::uint8_t spherical = 0;
  // What the point approximation's transfer is multiplied by.
  double transfer() const { return static_cast<double>(visibility) * static_cast<double>(extent); }
};

// The second-order correction of a link's transfer for the extent of its
// clusters: 1 + tr(H (C_x + C_y)) / (2 g), g the point kernel between the
// centres (facing along the clusters' axes), H its Hessian, C the clusters'
// area covariances. Measured by quadrature between two unit squares at twice
// the sum of their radii: the point approximation's transfer 8 to 11 % off,
// corrected within 1 %; at six times, 0.5 % and 0.01 %.
double extent_correction(const ClusterNode& receiver, const ClusterNode& emitter);

// The light a cluster sends, for the criterion: its luminance flux
// (sum of luminance(L) A over its sides) and the luminance of its brightest side.
struct ClusterLight {
  float flux = 0.0f;
  float peak = 0.0f;
};

// The light of every cluster node, and the flux of the sides summed in tree
// order (so shadow rays leave an emitter cluster where its light does).
struct ClusterLighting {
  std::vector<ClusterLight> nodes;
  std::vector<double> flux_prefix;  // sides() + 1 entries
};

// When the walk accepts a pair of clusters as one link (see above).
struct ClusterCriterion {
  double separation = 2.0;  // > 1; infinity: only pairs of sides
  // Of the link's error over adaptation x total area; infinity: separation alone.
  double threshold = 0.0;
  double adaptation = 0.0;  // radiance
  double total_area = 0.0;
  // ClusterGather::lighting, or estimated_cluster_light; none: separation alone.
  const ClusterLighting* lighting = nullptr;
  int rays = 16;  // shadow rays per cluster link
};

// The light each cluster sends before anything is solved: emitters their
// emission, reflecting sides their reflectance times `radiance` (the scene's
// reference radiance), so the first pass links by a guess that later passes
// correct (refinement reads the solved radiances).
ClusterLighting estimated_cluster_light(const ClusterTree& tree, const Hierarchy& hierarchy,
                                        double radiance);

struct InitialLinks {
  std::vector<ClusterLink> clusters;
  std::vector<Link> elements;  // candidate pairs of top-level elements, not yet evaluated
};

// The walk described above, from the root pair. Returns early (incomplete)
// once `cancelled` (called from worker threads, so it must be thread-safe)
// says so; `progress`, if set, hears the fraction of the walk done (from the
// walking thread).
InitialLinks link_clusters(const ClusterTree& tree, const Hierarchy& hierarchy,
                           const RayScene& scene, const ClusterCriterion& criterion,
                           const std::function<bool()>& cancelled,
                           const std::function<void(double)>& progress = {});

// Would `criterion` no longer accept this link (the light it carries grew, or
// the threshold fell)?
bool cluster_link_too_coarse(const ClusterTree& tree, const Hierarchy& hierarchy,
                             const ClusterLink& link, const ClusterCriterion& criterion);

// The walk from the children pairs of each of `links` (cluster links found too
// coarse): what replaces them.
InitialLinks split_cluster_links(const ClusterTree& tree, const Hierarchy& hierarchy,
                                 const RayScene& scene, const ClusterCriterion& criterion,
                                 std::span<const ClusterLink> links,
                                 const std::function<bool()>& cancelled);

// Marks every top-level element that a cluster link ends on (through a
// receiving cluster) and that faces some of what sends to it with
// `mark[element] = 1`: the sides that gather far light.
void mark_cluster_receivers(const ClusterTree& tree, const Hierarchy& hierarchy,
                            std::span<const ClusterLink> links, std::vector<std::uint8_t>& mark);

// What every top-level element gathers through the cluster links, at its
// samples (far light, first-order accurate over each receiving cluster), and
// the light each cluster sends (for the criterion). The emitters' power
// vectors go up the tree, the received vectors and gradients down, once per
// call.
class ClusterGather {
 public:
  // `links` are grouped by receiver (equal receivers consecutive: the solver
  // keeps them sorted). `gathered` is indexed by element id (top-level
  // elements come first) and is resized to hold every top-level element.
  void operator()(const ClusterTree& tree, const std::vector<ClusterLink>& links,
                  const Hierarchy& hierarchy, const std::vector<Rgb>& radiance,
                  std::vector<SampleRgb>& gathered);
  // Per cluster node, from the radiances of the last call.
  const ClusterLighting& lighting() const { return lighting_; }
  std::size_t memory_bytes() const;

 private:
  using ChannelVectors = std::array<dvec3, 3>;  // one vector per colour channel
  struct Received {
    ChannelVectors at_centre{};                       // S
    std::array<glm::mat3, 3> change{};                // G
    std::array<std::array<float, 9>, 3> harmonics{};  // of spherical links' light
  };
  std::vector<ChannelVectors> power_;  // per cluster node
  std::vector<Rgb> flux_;              // per cluster node: sum of L A
  ClusterLighting lighting_;
  std::vector<Received> received_;  // per cluster node
};

// Orders cluster links by receiver, then emitter (what ClusterGather reads).
void sort_by_receiver(std::vector<ClusterLink>& links);

}  // namespace radiosity
