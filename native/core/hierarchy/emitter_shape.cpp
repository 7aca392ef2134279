#include "core/hierarchy/emitter_shape.h"

#include <cmath>

#include "core/geometry/form_factor.h"

namespace radiosity {
namespace {

// Centres of the four children subdivide() makes, from the parent's corners.
int child_centres(const Hierarchy& hierarchy, const Element& e, dvec3* out) {
  dvec3 c[4];
  hierarchy.corners(e, c);
  if (e.corner_count == 4) {
    const dvec3 mid = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    for (int k = 0; k < 4; ++k)
      out[k] = 0.25 * (c[k] + 0.5 * (c[k] + c[(k + 1) % 4]) + mid + 0.5 * (c[k] + c[(k + 3) % 4]));
  } else {
    // Corner children are a half-size copy at each corner; the fourth is the middle one.
    const dvec3 centroid = (c[0] + c[1] + c[2]) / 3.0;
    for (int k = 0; k < 3; ++k) out[k] = 0.5 * (c[k] + centroid);
    out[3] = centroid;
  }
  return 4;
}

}  // namespace

EmitterShape emitter_shape(const Hierarchy& hierarchy, const Element& emitter,
                           std::span<const dvec3> receiver_polygon) {
  // Each child sends in proportion to its area (a quarter, but for the
  // children of a quad that is not a parallelogram, Hierarchy::subdivide) and
  // to how well it sees the receiver.
  double share[4];
  EmitterShape by_area;
  for (int c = 0; c < 4; ++c) {
    share[c] = hierarchy.element(emitter.first_child + c).area / emitter.area;
    by_area[static_cast<size_t>(c)] = static_cast<_Float16>(4.0 * share[c]);
  }
  if (!(luminance(hierarchy.reflectance(emitter)) > 0.0)) return by_area;
  dvec3 x[4];
  child_centres(hierarchy, emitter, x);
  const dvec3 normal = hierarchy.normal(emitter);
  double f[4];
  double mean = 0.0;
  for (int c = 0; c < 4; ++c) {
    f[c] = form_factor(x[c], normal, receiver_polygon);
    mean += share[c] * f[c];
  }
  if (!(mean > 0.0) || !std::isfinite(mean)) return by_area;
  EmitterShape shape;
  for (int c = 0; c < 4; ++c)
    shape[static_cast<size_t>(c)] = static_cast<_Float16>(4.0 * share[c] * f[c] / mean);
  return shape;
}

Rgb sent_radiance(const Hierarchy& hierarchy, std::int32_t emitter,
                  const std::vector<Rgb>& radiance, const EmitterShape& shape) {
  const Element& e = hierarchy.element(emitter);
  if (e.is_leaf() || !shape_computed(shape)) return radiance[static_cast<size_t>(emitter)];
  Rgb sum(0.0);
  double weight = 0.0;
  for (int c = 0; c < 4; ++c) {
    // The weights' sum renormalises half-precision rounding.
    const double w = static_cast<double>(shape[static_cast<size_t>(c)]);
    sum += w * radiance[static_cast<size_t>(e.first_child + c)];
    weight += w;
  }
  return weight > 0.0 ? sum / weight : radiance[static_cast<size_t>(emitter)];
}

}  // namespace radiosity
