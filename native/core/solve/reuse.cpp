#include "core/solve/reuse.h"

#include <cmath>

namespace radiosity {
namespace {

bool shines(const Rgb& c) { return c.x > 0.0 || c.y > 0.0 || c.z > 0.0; }

// Whether two sides are the same surface, whatever their lighting; `refusal`
// says which lighting change the kept links cannot carry.
bool same_side(const PatchSide& a, const PatchSide& b) {
  return a.present == b.present && a.face == b.face && a.face_side == b.face_side;
}

bool same_geometry(const Patch& a, const Patch& b) {
  if (a.corner_count != b.corner_count || a.normal != b.normal || a.area != b.area ||
      a.surface != b.surface || a.occludes != b.occludes || a.corner_class != b.corner_class ||
      a.edge_inset != b.edge_inset)
    return false;
  for (int k = 0; k < a.corner_count; ++k)
    if (a.corners[static_cast<size_t>(k)] != b.corners[static_cast<size_t>(k)]) return false;
  return same_side(a.sides[0], b.sides[0]) && same_side(a.sides[1], b.sides[1]);
}

bool same_geometry(const Light& a, const Light& b) {
  return a.kind == b.kind && a.position == b.position && a.direction == b.direction &&
         a.radius == b.radius && a.sphere == b.sphere && a.angle == b.angle &&
         a.cos_half_angle == b.cos_half_angle && a.blend_width == b.blend_width &&
         a.cosine_falloff == b.cosine_falloff;
}

RelightRefusal options_refusal(const SolveOptions& a, const SolveOptions& b) {
  if (a.oracle != b.oracle) return RelightRefusal::OracleChanged;
  if (a.quality != b.quality) return RelightRefusal::QualityChanged;
  if (a.visibility != b.visibility || a.rays != b.rays || a.faint_share != b.faint_share)
    return RelightRefusal::VisibilityChanged;
  if (a.bounces || b.bounces) return RelightRefusal::FixedBounces;
  if (a.min_element_area != b.min_element_area) return RelightRefusal::SmallestElementChanged;
  if (a.leaf_links != b.leaf_links || a.cluster_separation != b.cluster_separation ||
      a.dim_share != b.dim_share)
    return RelightRefusal::LinkingChanged;
  return RelightRefusal::None;
}

}  // namespace

RelightRefusal relight_refusal(const Scene& kept, const SolveOptions& kept_options,
                               const Scene& scene, const SolveOptions& options) {
  if (const RelightRefusal why = options_refusal(kept_options, options);
      why != RelightRefusal::None)
    return why;
  if (kept.patches.size() != scene.patches.size() ||
      kept.occluders.size() != scene.occluders.size())
    return RelightRefusal::GeometryChanged;
  // A light (or the world) that gives nothing is left out of the scene (make_scene).
  if (kept.lights.size() != scene.lights.size()) return RelightRefusal::LightsAddedOrRemoved;
  for (size_t i = 0; i < kept.occluders.size(); ++i)
    if (!same_geometry(kept.occluders[i], scene.occluders[i]))
      return RelightRefusal::GeometryChanged;
  for (size_t i = 0; i < kept.lights.size(); ++i)
    if (!same_geometry(kept.lights[i], scene.lights[i])) return RelightRefusal::LightChanged;
  for (size_t i = 0; i < kept.patches.size(); ++i) {
    const Patch &a = kept.patches[i], &b = scene.patches[i];
    if (!same_geometry(a, b)) return RelightRefusal::GeometryChanged;
    for (size_t s = 0; s < 2; ++s) {
      if (shines(b.sides[s].emission) && !shines(a.sides[s].emission))
        return RelightRefusal::NowEmits;
      if (shines(b.sides[s].reflectance) && !shines(a.sides[s].reflectance))
        return RelightRefusal::NowReflects;
    }
  }
  return RelightRefusal::None;
}

double lighting_scale(const Scene& kept, const Scene& scene) {
  auto lighting = [](const Scene& s) {
    double sum = s.emitted_power;
    for (const Light& light : s.lights) sum += luminance(light.colour);
    return sum;
  };
  const double before = lighting(kept), after = lighting(scene);
  return before > 0.0 && after > 0.0 ? after / before : 1.0;
}

void take_lighting(Scene& kept, const Scene& scene) {
  for (size_t i = 0; i < kept.patches.size(); ++i) {
    for (size_t s = 0; s < 2; ++s) {
      kept.patches[i].sides[s].emission = scene.patches[i].sides[s].emission;
      kept.patches[i].sides[s].reflectance = scene.patches[i].sides[s].reflectance;
    }
  }
  for (size_t i = 0; i < kept.occluders.size(); ++i)
    kept.occluders[i].sides = scene.occluders[i].sides;
  for (size_t i = 0; i < kept.lights.size(); ++i) kept.lights[i].colour = scene.lights[i].colour;
  kept.emitted_power = scene.emitted_power;
}

}  // namespace radiosity
