// What one link p <- q carries (DESIGN s5): the form factor from each sample of
// the receiver to the emitter element, with visibility, and the geometric part
// of the oracle's criterion. Visibility is shaft-culled once per link; partially
// occluded links use the exact visible polygon or sampled shadow rays.
#pragma once

#include <array>
#include <cstdint>
#include <memory>

#include "core/hierarchy.h"
#include "core/oracle.h"
#include "core/ray_scene.h"
#include "core/shaft.h"

namespace radiosity {

enum class VisibilityMode : std::uint8_t { Exact, Sampled };

struct Link {
  std::int32_t receiver = kNone;
  std::int32_t emitter = kNone;
  std::array<float, kMaxSamples> form_factor{};  // per receiver sample
  // Geometric part of the refinement criterion over the oracle's geometric
  // scale (oracle_geometric_scale): dimensionless.
  float oracle = 0.0f;
};

// CPU seconds spent in each part of link evaluation (summed over threads).
struct LinkTimings {
  double visibility = 0.0;
  double form_factors = 0.0;
  double oracle = 0.0;
  LinkTimings& operator+=(const LinkTimings& o) {
    visibility += o.visibility;
    form_factors += o.form_factors;
    oracle += o.oracle;
    return *this;
  }
};

// The occluders of a scene: one or two triangles per patch, tagged with the
// input face so a link never shadows itself.
struct SceneOccluders {
  OccluderScene shafts;
  std::unique_ptr<RayScene> rays;  // only for sampled visibility
};

SceneOccluders make_scene_occluders(const Scene& scene, VisibilityMode mode);

struct LinkEvaluator {
  const Hierarchy& hierarchy;
  const SceneOccluders& occluders;
  VisibilityMode visibility = VisibilityMode::Exact;
  int rays = 16;
  Oracle oracle = Oracle::Standard;
  double geometric_scale = 1.0;  // oracle_geometric_scale() of the scene

  // Fills `link.form_factor` and `link.oracle`; false when the emitter is not
  // seen from any sample (facing away, coplanar or fully hidden).
  bool evaluate(Link& link, LinkTimings& timings) const;
};

// Could any part of `emitter` send light to any part of `receiver`? The facing
// test of initial linking, before any visibility work.
bool elements_face_each_other(const Hierarchy& hierarchy, const Element& receiver,
                              const Element& emitter);

}  // namespace radiosity
