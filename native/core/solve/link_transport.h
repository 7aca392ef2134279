// What one link p <- q carries (DESIGN s5): the form factor from each sample of
// the receiver to the emitter element, with visibility, and the geometric part
// of the oracle's criterion. Visibility is shaft-culled once per link; partially
// occluded links use the exact visible polygon or sampled shadow rays.
#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string_view>

#include "core/geometry/form_factor.h"
#include "core/hierarchy/emitter_shape.h"
#include "core/hierarchy/hierarchy.h"
#include "core/solve/faint_samples.h"
#include "core/solve/oracle.h"
#include "core/visibility/occluders.h"
#include "core/visibility/ray_scene.h"
#include "core/visibility/shaft.h"
#include "radiosity/solve.h"

namespace radiosity {

struct Link {
  std::int32_t receiver = kNone;
  std::int32_t emitter = kNone;
  std::array<float, kMaxSamples> form_factor{};  // per receiver sample
  // Geometric part of the refinement criterion over the oracle's geometric
  // scale (oracle_geometric_scale): dimensionless.
  float oracle = 0.0f;
  // How F varies over the emitter (emitter_shape.h), so a split emitter sends
  // more from where it sees the receiver better. Computed once the emitter is split.
  EmitterShape emitter_shape = kShapeNotComputed;
};

// Form factors already computed at the corners of sibling receivers linked to
// the same emitter. The four children of a split receiver share 9 of their 16
// corners (quads) or 6 of 12 (triangles), so a group evaluated together computes
// each shared corner once: about a third fewer visible polygons. Corner samples
// sit a millionth of the element's size inside their own element, so a shared
// value is taken that far from where the sibling would have sampled it.
class CornerMemo {
 public:
  // Forgets everything when the emitter changes.
  void use_emitter(std::int32_t emitter) {
    if (emitter != emitter_) count_ = 0;
    emitter_ = emitter;
  }
  const FormFactorGradient* find(std::uint32_t vertex) const {
    for (int i = 0; i < count_; ++i)
      if (vertex_[static_cast<size_t>(i)] == vertex) return &value_[static_cast<size_t>(i)];
    return nullptr;
  }
  void add(std::uint32_t vertex, const FormFactorGradient& value) {
    if (count_ == kCapacity) return;
    vertex_[static_cast<size_t>(count_)] = vertex;
    value_[static_cast<size_t>(count_++)] = value;
  }

 private:
  static constexpr int kCapacity = 9;
  std::int32_t emitter_ = kNone;
  int count_ = 0;
  std::array<std::uint32_t, kCapacity> vertex_{};
  std::array<FormFactorGradient, kCapacity> value_{};
};

struct LinkEvaluator {
  const Hierarchy& hierarchy;
  const SceneOccluders& occluders;
  VisibilityMode visibility = VisibilityMode::Exact;
  int rays = 16;
  Oracle oracle = Oracle::Standard;
  double geometric_scale = 1.0;  // oracle_geometric_scale() of the scene
  // With exact visibility, the samples shadowed by rays instead; null or
  // empty: none.
  const FaintSamples* faint = nullptr;

  // Fills `link.form_factor` and `link.oracle`; false when the emitter is not
  // seen from any sample (facing away, coplanar or fully hidden). With a memo,
  // corner values are shared with the siblings evaluated before (same emitter).
  bool evaluate(Link& link, LinkTimings& timings, CornerMemo* memo = nullptr) const;

  // Links from one receiver to two to four children of one emitter element (a
  // split emitter): the parent's shaft and visible region are computed once per
  // sample and clipped to each child (exact visibility; sampled visibility
  // evaluates them one by one). visible[i] is evaluate()'s answer for links[i].
  void evaluate_emitter_siblings(std::span<Link> links, LinkTimings& timings,
                                 std::span<std::uint8_t> visible) const;
};

// Could any part of `emitter` send light to any part of `receiver`? The facing
// test of initial linking, before any visibility work.
bool elements_face_each_other(const Hierarchy& hierarchy, const Element& receiver,
                              const Element& emitter);

}  // namespace radiosity
