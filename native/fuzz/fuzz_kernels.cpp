// libFuzzer harness of the form-factor kernels (`make fuzz`): the point-to-polygon
// form factor and its gradient (form_factor.h) on what the Python bindings let
// through, and the patch-to-patch form factor (patch_form_factor.h) on any
// polygons of up to 16 vertices, which it must take as they come (0 for
// degenerate or non-finite input). Findings: a sanitizer report, a non-finite
// value, F outside [0, 1], a hang (libFuzzer's -timeout).
//
// Input: u8 flags; point (3 f64); normal (3 f64); polygon p; polygon q
// (fuzz_input.h, read_polygon).
#include <cstddef>
#include <cstdint>
#include <stdexcept>

#include "core/geometry/form_factor.h"
#include "core/geometry/patch_form_factor.h"
#include "fuzz/fuzz_input.h"

using namespace radiosity;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  fuzz::Reader in(data, size);
  const std::uint8_t flags = in.u8();
  const dvec3 point = in.vec3();
  const dvec3 raw_normal = in.vec3();
  const std::vector<dvec3> p = fuzz::read_polygon(in, 16);
  const std::vector<dvec3> q = fuzz::read_polygon(in, 16);

  // As _radiosity.form_factor() and form_factor_gradient() call them.
  dvec3 normal;
  if (fuzz::in_range(point) && fuzz::unit_normal(raw_normal, normal) && fuzz::valid_polygon(p)) {
    // To a planar convex polygon (what the solver passes) F is a share of the
    // hemisphere; the kernels take any polygon, whose F must only be finite.
    const bool bounded = fuzz::planar_convex(p);
    const double f = form_factor(point, normal, p);
    fuzz::require_finite(f, "form_factor: F");
    if (bounded && (f < -1e-9 || f > 1.0 + 1e-9)) fuzz::fail("form_factor: F outside [0, 1]", f);
    const FormFactorGradient g = form_factor_gradient(point, normal, p);
    fuzz::require_finite(g.value, "form_factor_gradient: F");
    fuzz::require_finite(g.gradient, "form_factor_gradient: grad F");
    if (bounded && (g.value < -1e-9 || g.value > 1.0 + 1e-9))
      fuzz::fail("form_factor_gradient: F outside [0, 1]", g.value);
  }

  // The solver calls it with convex patches; its contract takes anything of
  // 3 to 16 vertices within kMaxCoordinate (what a Scene holds) and returns 0
  // for what it cannot integrate.
  const auto within = [](const std::vector<dvec3>& polygon) {
    return std::all_of(polygon.begin(), polygon.end(),
                       [](const dvec3& v) { return fuzz::in_range(v); });
  };
  if ((flags & 1) && within(p) && within(q)) {
    double f = 0.0;
    try {
      f = patch_form_factor(p, q, (flags & 2) ? 1e-6 : 1e-12);
    } catch (const std::invalid_argument&) {
      fuzz::fail("patch_form_factor threw for at most 16 vertices");
    }
    fuzz::require_finite(f, "patch_form_factor: F");
    // Between two planar convex polygons (what the solver passes) F is a
    // fraction: of what leaves p, the share that reaches q.
    const bool proper = fuzz::valid_polygon(p) && fuzz::valid_polygon(q) &&
                        fuzz::planar_convex(p) && fuzz::planar_convex(q);
    // (-1e-20 at the rounding of a 1e-9 scene is no finding.)
    if (proper && (f < -1e-12 || f > 1.0 + 1e-6))
      fuzz::fail("patch_form_factor: F outside [0, 1]", f);
  }
  return 0;
}
