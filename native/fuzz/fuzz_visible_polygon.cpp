// libFuzzer harness of visible-polygon clipping (visible_polygon.h, `make fuzz`):
// the visible part of a planar convex emitter from a point past any triangles,
// its exact form factor and gradient, and the same for the emitter's fan
// triangles at once (visible_form_factor_gradient_parts, as a split emitter is
// evaluated). The emitter, point and normal pass the checks the Python
// bindings make (visible_polygon(), visible_form_factor()); occluders are any
// triangles within kMaxCoordinate (include/radiosity/scene.h), as the bindings take them.
// Findings: a sanitizer report, a non-finite value, a hang.
//
// Input: u8 flags; point; normal; emitter (fuzz_input.h, read_polygon); u16
// occluder count (at most 48); per occluder u8 kind and its vertices (kind 0:
// three raw vertices; 1: a triangle between the point and the emitter's centre,
// at a fraction along the line, of a size, turned by a vector; 2: a raw
// triangle with one vertex on the point; 3: on an emitter vertex).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "core/geometry/triangle.h"
#include "core/visibility/visible_polygon.h"
#include "fuzz/fuzz_input.h"

using namespace radiosity;

namespace {

std::vector<Triangle> read_occluders(fuzz::Reader& in, const dvec3& point,
                                     std::span<const dvec3> emitter) {
  const std::size_t m = in.count(48);
  dvec3 centre(0.0);
  for (const dvec3& v : emitter) centre += v / static_cast<double>(emitter.size());
  std::vector<Triangle> out;
  for (std::size_t t = 0; t < m; ++t) {
    const std::uint8_t kind = in.u8() % 4;
    Triangle tri;
    if (kind == 1) {
      const double along = in.f64(), size = in.f64();
      const dvec3 c = point + along * (centre - point);
      for (dvec3& v : tri.v) v = c + size * in.vec3();
    } else {
      for (dvec3& v : tri.v) v = in.vec3();
      if (kind == 2) tri.v[0] = point;
      if (kind == 3) tri.v[0] = emitter[in.u8() % emitter.size()];
    }
    bool ok = true;
    for (const dvec3& v : tri.v) ok = ok && fuzz::in_range(v);
    if (ok) out.push_back(tri);  // the bindings refuse occluders out of range
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Reader in(data, size);
  const std::uint8_t flags = in.u8();
  const dvec3 point = in.vec3();
  dvec3 normal;
  const bool normal_ok = fuzz::unit_normal(in.vec3(), normal);
  const std::vector<dvec3> emitter = fuzz::read_polygon(in, 12);
  if (!normal_ok || !fuzz::in_range(point) || !fuzz::valid_polygon(emitter) ||
      !fuzz::planar_convex(emitter))
    return 0;
  const std::vector<Triangle> occluders = read_occluders(in, point, emitter);

  const VisiblePolygon visible = visible_polygon(point, normal, emitter, occluders);
  for (const VisiblePiece& piece : visible.pieces) {
    for (const ContourVertex& v : piece) {
      fuzz::require_finite(v.position, "visible_polygon: piece position");
      fuzz::require_finite(v.anchor, "visible_polygon: piece anchor");
    }
  }
  const FormFactorGradient whole = visible_form_factor_gradient(point, normal, emitter, occluders);
  fuzz::require_finite(whole.value, "visible_form_factor_gradient: F");
  fuzz::require_finite(whole.gradient, "visible_form_factor_gradient: grad F");

  if (flags & 1) {
    // The emitter's fan triangles, as the parts of a split emitter.
    std::vector<std::array<dvec3, 3>> fan;
    for (std::size_t i = 1; i + 1 < emitter.size(); ++i)
      fan.push_back({emitter[0], emitter[i], emitter[i + 1]});
    std::vector<std::span<const dvec3>> parts;
    for (const auto& t : fan) parts.emplace_back(t.data(), t.size());
    std::vector<FormFactorGradient> out(parts.size());
    visible_form_factor_gradient_parts(point, normal, emitter, parts, occluders, out);
    for (const FormFactorGradient& g : out) {
      fuzz::require_finite(g.value, "visible_form_factor_gradient_parts: F");
      fuzz::require_finite(g.gradient, "visible_form_factor_gradient_parts: grad F");
    }
  }
  return 0;
}
