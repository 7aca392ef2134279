// Energy balance of the transport: two corrections that make what the links
// carry add up, both computed from the links alone (geometry, not radiance),
// once per change of the links. Both rest on the closure of a point: the
// fraction of its hemisphere the linked surfaces cover (their form factors
// summed), 1 everywhere inside a closed room.
//
// Receiving. A split receiver keeps its far links and hands only near-field
// ones to its children (leaf_links "near"): what its children's samples get
// from the far links is the parent's interpolant, whose error is the error of
// interpolating those links' form factors (the furnace, every surface
// emitting and reflecting alike, came out 0.4 % off at rho = 0.5 and 1.4 % at
// 0.9). Where a point sees nothing but linked surfaces (inside a closed room)
// its closure is exactly 1, whatever the far links' interpolation says. Each
// element's closure is known at its samples (from its links for the
// top-level elements, pushed down from the parent for the others); at a leaf
// sample whose closure is 1 (to 1e-3), what its ancestors pushed down is
// scaled so that the form factors there sum to 1:
//   H = H_own + H_down (1 - F_own) / F_down.
// Elsewhere (near an opening, a black surface) the closure varies as fast as
// what it would correct, and nothing is scaled.
//
// Sending. A link p <- X carries the exact exchange between p and X (the
// energy correction of link_transport), but it takes X's light as one
// average: every part l of X is sent as if its form factor to p were X's
// average. Summed over all the links a part's light leaves through, the
// fraction it delivers, D_l, ranges from 0.85 to 1.45 in a lit room (the area
// mean is the true one), and where it correlates with the part's radiance
// light is lost or made: 0.3 % per bounce in a white room, so 0.6 % of the
// power at rho = 0.5 and 5 % at 0.99. Reciprocity says what D_l should be: the
// closure of l, over the surfaces that receive (reflect). Each leaf therefore
// sends, instead of its radiance L_l,
//   lambda L_R + (L_l - L_R) C_l / D_l,
// with L_R the mean radiance of its top-level element R and lambda =
// sum(A C) / sum(A D) over R: the deviation from the mean leaves in the
// proportion the leaf's closure asks, the mean in the proportion R's links
// carry as a whole, so that R delivers sum(A_l C_l L_l), and a uniformly
// bright surface (the furnace) is sent unchanged. D_l is what the receivers'
// leaves gather from l, the receiving correction's factors included: else the
// light that correction adds is made at every bounce (a white room with a box,
// lit by a light that casts no shadow: 13 % at rho 0.99). Inner elements send the
// area average of their leaves. Surfaces that reflect nothing are not
// balanced on either side: they have no receiver links to know a closure by,
// and an emitter's own light is uniform.
//
// Closure from the scene. The links' form factors at a point do not sum to
// exactly its closure: each link carries the exact exchange of its two
// elements, so its values at the samples lean (a corner of a ceiling a
// centimetre above a lamp's cover sums to 0.95, a wall's corners to 0.96 to
// 1.01). Taken as C_l, that shortfall is light lost at every bounce (1 % of
// the power at rho = 0.9, 11 % at 0.99, in a closed room with a lamp under
// its ceiling). The ray pass counts the share f of a top-level element's rays
// that leave for the sky or meet the back of a one-sided face (set_escaped).
// Where nothing escapes, C_l is 1 less the share its links give to surfaces
// that do not reflect, and conservation holds by construction: every leaf
// delivers what it sends. The more escapes, the less that is trusted: C_l
// moves linearly to the links' own sum by f = kTrustRays (a few rays: beside
// a window the leaves' closure varies too much for the element's one number). A yes-or-no
// "enclosed" flipped with the last bits of the coordinates for a wall whose
// top edge sees a lamp's back at a grazing angle (one ray in 2,048), moving
// that wall's light by 0.7 %.
#pragma once

#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "core/hierarchy/cluster_tree.h"
#include "core/hierarchy/hierarchy.h"
#include "core/solve/cluster_links.h"
#include "core/solve/gather.h"
#include "core/solve/link_transport.h"

namespace radiosity {

class EnergyBalance {
 public:
  // Recomputes both corrections for the current links. `grouping` gathers over
  // them (its `source` is ignored); `far` are the cluster links (may be empty,
  // and then `tree` may have been released).
  void update(const Hierarchy& hierarchy, const LinkGather& grouping, const ClusterTree& tree,
              const std::vector<ClusterLink>& far, ClusterGather& far_gather);

  // Per top-level element (indexed by element id, as RayPass::escaped): the
  // share of its hemisphere that escapes. Kept across updates; empty (the
  // links' sums alone) until the ray pass has run.
  void set_escaped(std::vector<float> escaped) { escaped_ = std::move(escaped); }

  // Per element, the factor on what each leaf sample receives from its
  // ancestors (push_pull's `down_scale`); empty before the first update.
  const std::vector<SampleScale>& down_scale() const { return down_scale_; }

  // The radiance each element sends, from the radiances push/pull left.
  void sent_radiances(const Hierarchy& hierarchy, std::vector<Rgb>& sent) const;

  std::size_t memory_bytes() const;

 private:
  std::vector<SampleScale> closure_;     // per element, at its samples: all linked emitters
  std::vector<SampleScale> down_scale_;  // per element (leaves), at its samples
  std::vector<float> leaf_scale_;  // C_l / D_l per element (1 where not balanced or not a leaf)
  std::vector<float> root_scale_;  // lambda per root slot (2 patch + side)
  std::vector<float> escaped_;     // per top-level element id
};

}  // namespace radiosity
