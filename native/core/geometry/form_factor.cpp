#include "core/geometry/form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace radiosity {
namespace {

const dvec3& position_of(const dvec3& v) { return v; }
const dvec3& position_of(const ContourVertex& v) { return v.position; }

// Horizon-clip points of a polygon with fixed edges may be treated as fixed:
// they slide along their edge, and along the horizon the integrand's cosine
// vanishes (MATH.md s2). A clipped edge of a depth-clipped emitter may itself
// move (an occluder edge seen from r), so there the clip point remembers the
// edge's 3D line and gets its own Jacobian.
dvec3 clipped_vertex(const dvec3&, const dvec3&, const dvec3&, const dvec3& at) { return at; }

// The 3D line that generates the contour edge a -> b: the line through two
// intrinsic anchors, else the line of an apparent vertex that lies in the
// edge's plane through r.
Line edge_line(const ContourVertex& a, const ContourVertex& b, const dvec3& r) {
  const dvec3 plane_normal = glm::normalize(glm::cross(a.position - r, b.position - r));
  Line best{a.anchor, b.anchor - a.anchor};
  double best_alignment = 2.0;
  for (const ContourVertex* v : {&a, &b}) {
    if (!v->apparent && !v->horizon) continue;
    for (const Line* line : {&v->s, &v->t}) {
      if (v->horizon && line == &v->t) continue;
      const double alignment = std::abs(glm::dot(plane_normal, glm::normalize(line->direction)));
      if (alignment < best_alignment) best_alignment = alignment, best = *line;
    }
  }
  return best;
}

ContourVertex clipped_vertex(const ContourVertex& a, const ContourVertex& b, const dvec3& r,
                             const dvec3& at) {
  if (!a.apparent && !a.horizon && !b.apparent && !b.horizon && a.anchor == a.position &&
      b.anchor == b.position) {
    return ContourVertex::intrinsic(at);  // a fixed edge of the emitter itself
  }
  ContourVertex v = ContourVertex::intrinsic(at);
  v.horizon = true;
  v.s = edge_line(a, b, r);
  return v;
}

// Polygon storage that lives on the stack for the sizes the solver meets
// (triangles, quads, visible pieces), and on the heap beyond.
template <class Vertex>
class PolygonBuffer {
 public:
  explicit PolygonBuffer(size_t capacity) {
    if (capacity > inline_.size()) heap_.resize(capacity);
  }
  Vertex* data() { return heap_.empty() ? inline_.data() : heap_.data(); }

 private:
  std::array<Vertex, 32> inline_;  // left uninitialised: filled before use
  std::vector<Vertex> heap_;
};

// Receiver strictly in front of the polygon: above its plane by more than
// every vertex is, and by more than the polygon's own thickness (a polygon
// planar to 1e-9 of its size may have a corner 6e-9 long twisted by 30
// degrees; from 3e-10 above it F was -6.5e-4: libFuzzer kernels, crash-dd8d717d). The normal comes
// from edges relative to v0 (Newell's method on absolute coordinates fails for tiny, distant
// polygons). Heights are measured the same way for the receiver and for the vertices, so what the
// normal gets wrong (its direction is only good to about eps / sin of the
// polygon's sharpest fan angle: a sliver triangle 1e-5 wide tilts it by 1e-11)
// and what a nearly planar polygon leaves off its plane move both alike: a
// receiver on a vertex is never in front of it (a receiver on a vertex of a
// sliver, 1e-10 "in front" of v0's plane, gave F = -0.54; atheris finding 1).
// "On the plane" also allows for the rounding of the coordinates and a tiny
// fraction of the polygon's size (MATH.md s3), so a receiver 1e-9 of the
// emitter's size away still sees it.
template <class Vertex>
bool receiver_in_front(const dvec3& r, std::span<const Vertex> polygon) {
  const dvec3& v0 = position_of(polygon[0]);
  dvec3 area_normal(0.0);
  double diameter = 0.0;
  for (size_t i = 1; i + 1 < polygon.size(); ++i) {
    const dvec3 a = position_of(polygon[i]) - v0;
    const dvec3 b = position_of(polygon[i + 1]) - v0;
    area_normal += glm::cross(a, b);
    diameter = std::max(diameter, glm::length(a));
  }
  diameter = std::max(diameter, glm::length(position_of(polygon.back()) - v0));
  const double twice_area = glm::length(area_normal);
  if (!(twice_area > 0.0)) return false;
  const dvec3 normal = area_normal / twice_area;
  double top = 0.0, bottom = 0.0;  // v0's height is 0
  for (size_t i = 1; i < polygon.size(); ++i) {
    const double h = glm::dot(normal, position_of(polygon[i]) - v0);
    top = std::max(top, h);
    bottom = std::min(bottom, h);
  }
  const double height = glm::dot(normal, r - v0);
  const double rounding = 1e-15 * (glm::length(r) + glm::length(v0));
  return height > top + (top - bottom) + 1e-12 * diameter + rounding;
}

// Height of a vertex above the receiver's horizon; a vertex below it only by
// rounding counts as on it, so no sliver piece is clipped off.
double horizon_height(const dvec3& r, const dvec3& n, const dvec3& p) {
  const dvec3 d = p - r;
  const double h = glm::dot(n, d);
  return h < 0.0 && h > -1e-14 * glm::length(d) ? 0.0 : h;
}

// Sutherland-Hodgman clip to the receiver's upper half-space n.(x - r) >= 0.
// Returns the vertex count written to `out` (room for 2n vertices).
template <class Vertex>
size_t clip_to_horizon(const dvec3& r, const dvec3& n, std::span<const Vertex> in, Vertex* out) {
  size_t count = 0;
  const size_t size = in.size();
  for (size_t i = 0; i < size; ++i) {
    const Vertex& a = in[i];
    const Vertex& b = in[(i + 1) % size];
    const double ha = horizon_height(r, n, position_of(a));
    const double hb = horizon_height(r, n, position_of(b));
    if (ha >= 0.0) out[count++] = a;
    if ((ha >= 0.0) != (hb >= 0.0)) {
      const double t = ha / (ha - hb);
      const dvec3 at = position_of(a) + t * (position_of(b) - position_of(a));
      out[count++] = clipped_vertex(a, b, r, at);
    }
  }
  return count;
}

// Calls `integrate(polygon)` on the part of `polygon` above the receiver's
// horizon, clipping only when some vertex lies below it.
template <class Vertex, class Integrate>
auto with_horizon_clip(const dvec3& r, const dvec3& n, std::span<const Vertex> polygon,
                       Integrate&& integrate) {
  bool below = false;
  for (const Vertex& v : polygon) below |= horizon_height(r, n, position_of(v)) < 0.0;
  if (!below) return integrate(polygon);
  PolygonBuffer<Vertex> buffer(2 * polygon.size());
  const size_t count = clip_to_horizon(r, n, polygon, buffer.data());
  return integrate(std::span<const Vertex>(buffer.data(), count));
}

// Per-edge quantities of eq. 4 in the robust form of MATH.md s1: the edge vector
// is taken from stored vertices so tiny emitters keep full relative precision.
struct EdgeTerm {
  dvec3 edge;    // e_i = v_(i+1) - v_i
  dvec3 c;       // e_i x p_i, normal of the plane through r and the edge
  double s;      // |c|
  double d;      // p_i . p_(i+1)
  double theta;  // angle subtended by the edge
};

EdgeTerm edge_term(const dvec3& vi, const dvec3& vj, const dvec3& pi, const dvec3& pj) {
  EdgeTerm t;
  t.edge = vj - vi;
  t.c = glm::cross(t.edge, pi);
  t.s = glm::length(t.c);
  t.d = glm::dot(pi, pj);
  t.theta = std::atan2(t.s, t.d);
  return t;
}

FormFactorGradient finite_or_zero(const FormFactorGradient& result) {
  const bool finite = std::isfinite(result.value) && std::isfinite(result.gradient.x) &&
                      std::isfinite(result.gradient.y) && std::isfinite(result.gradient.z);
  return finite ? result : FormFactorGradient{};
}

// F is dimensionless, but the edge terms hold products of up to four lengths
// (|c|^2, s^2 + d^2): below about 1e-77 they underflow (F = -0.24 instead of
// 0.21 for a polygon 4e-81 across; libFuzzer kernels, crash-8fd16867) and
// above about 1e77 they overflow. Such input is moved to r = 0 and scaled by
// a power of two to unit size, where it is evaluated; within that range
// nothing changes (a power-of-two scale is exact, so even there the result
// would be the same bits but for the move). `scale` is 0 when no rescaling is
// needed.
struct Rescaled {
  PolygonBuffer<dvec3> polygon;
  double scale = 0.0;
  explicit Rescaled(size_t n) : polygon(n) {}
};

Rescaled rescale(const dvec3& r, std::span<const dvec3> polygon) {
  Rescaled out(polygon.size());
  double extent = 0.0;
  for (const dvec3& v : polygon) {
    const dvec3 d = glm::abs(v - r);
    extent = std::max(extent, std::max(d.x, std::max(d.y, d.z)));
  }
  constexpr double kLow = 0x1p-200, kHigh = 0x1p+200;
  if (!(extent > 0.0) || !std::isfinite(extent) || (extent >= kLow && extent <= kHigh)) return out;
  out.scale = std::ldexp(1.0, -std::ilogb(extent));
  for (size_t i = 0; i < polygon.size(); ++i) out.polygon.data()[i] = (polygon[i] - r) * out.scale;
  return out;
}

}  // namespace

double form_factor(const dvec3& r, const dvec3& n, std::span<const dvec3> polygon) {
  if (polygon.size() < 3) return 0.0;
  if (Rescaled moved = rescale(r, polygon); moved.scale != 0.0) {
    return form_factor(dvec3(0.0), n, std::span<const dvec3>(moved.polygon.data(), polygon.size()));
  }
  if (!receiver_in_front(r, polygon)) return 0.0;
  const double value = with_horizon_clip(r, n, polygon, [&](std::span<const dvec3> poly) {
    double sum = 0.0;
    const size_t size = poly.size();
    for (size_t i = 0; i < size; ++i) {
      const dvec3& vj = poly[(i + 1) % size];
      const EdgeTerm t = edge_term(poly[i], vj, poly[i] - r, vj - r);
      if (t.s > 0.0) sum += t.theta * glm::dot(n, t.c) / t.s;  // skip only when s = 0
    }
    return sum * kInvTwoPi;
  });
  return std::isfinite(value) ? value : 0.0;
}

FormFactorGradient form_factor_gradient(const dvec3& r, const dvec3& n,
                                        std::span<const dvec3> polygon) {
  if (polygon.size() < 3) return {};
  if (Rescaled moved = rescale(r, polygon); moved.scale != 0.0) {
    // r' = (r - r0) scale: dF/dr = scale dF/dr'.
    FormFactorGradient g = form_factor_gradient(
        dvec3(0.0), n, std::span<const dvec3>(moved.polygon.data(), polygon.size()));
    g.gradient *= moved.scale;
    return finite_or_zero(g);
  }
  if (!receiver_in_front(r, polygon)) return {};
  return finite_or_zero(with_horizon_clip(r, n, polygon, [&](std::span<const dvec3> poly) {
    // grad F = 1/2pi sum [g_i grad theta_i + theta_i grad g_i], finite where an edge
    // subtends 90 degrees (the printed edge matrix divides by a.b there).
    FormFactorGradient result;
    const size_t size = poly.size();
    for (size_t i = 0; i < size; ++i) {
      const dvec3& vj = poly[(i + 1) % size];
      const dvec3 pi = poly[i] - r;
      const dvec3 pj = vj - r;
      const EdgeTerm t = edge_term(poly[i], vj, pi, pj);
      if (!(t.s > 0.0)) continue;
      const dvec3 c_hat = t.c / t.s;
      const double g = glm::dot(n, c_hat);
      const dvec3 grad_theta =
          (t.d * glm::cross(t.edge, c_hat) + t.s * (pi + pj)) / (t.s * t.s + t.d * t.d);
      const dvec3 grad_g = glm::cross(t.edge, n - g * c_hat) / t.s;
      result.value += t.theta * g;
      result.gradient += g * grad_theta + t.theta * grad_g;
    }
    result.value *= kInvTwoPi;
    result.gradient *= kInvTwoPi;
    return result;
  }));
}

namespace {

// Distance along the unit ray r + alpha u to the line it meets.
double distance_to_line(const dvec3& r, const dvec3& u, const Line& line) {
  const dvec3 u_x_s = glm::cross(u, line.direction);
  const double denom = glm::dot(u_x_s, u_x_s);
  if (!(denom > 0.0)) return glm::length(line.point - r);
  return glm::dot(glm::cross(line.point - r, line.direction), u_x_s) / denom;
}

// J^T g for the vertex Jacobian J = du/dr of a contour vertex seen along unit u
// at distance `alpha`: eq. 15 for intrinsic vertices, eq. 14 (in the inverse-free
// form of MATH.md s2) for apparent ones.
dvec3 vertex_jacobian_transpose_times(const ContourVertex& v, const dvec3& r, const dvec3& n,
                                      const dvec3& u, const dvec3& g) {
  const dvec3 g_tangent = g - u * glm::dot(u, g);
  if (v.horizon) {
    // u = w / |w| with w = n x m and m = (P - r) x d the normal of the plane
    // through r and the edge's 3D line (P, d): dm = d x dr, so
    // J^T g = d x (n x g_tangent) / |w|, oriented so that u points at the vertex.
    const dvec3& d = v.s.direction;
    const dvec3 m = glm::cross(v.s.point - r, d);
    const dvec3 w = glm::cross(n, m);
    const double length = glm::length(w);
    // An edge lying along the horizon: its plane is the tangent plane and the
    // crossing is ill-defined; the vertex then moves like a fixed point.
    if (!(length > 1e-9 * glm::length(m))) return -g_tangent / glm::length(v.position - r);
    const double sign = glm::dot(w, u) >= 0.0 ? 1.0 : -1.0;
    return sign * glm::cross(d, glm::cross(n, g_tangent)) / length;
  }
  if (v.apparent) {
    const dvec3 s = glm::normalize(v.s.direction);
    const dvec3 t = glm::normalize(v.t.direction);
    const dvec3 t_x_u = glm::cross(t, u);
    const dvec3 u_x_s = glm::cross(u, s);
    const double det = glm::dot(s, t_x_u);
    if (std::abs(det) > 1e-12) {
      // s_hat takes eigenvalue -1/alpha_t (the distance to the *other* line), t_hat -1/alpha_s.
      const double alpha_s = distance_to_line(r, u, v.s);
      const double alpha_t = distance_to_line(r, u, v.t);
      const dvec3 s_hat = s - u * glm::dot(u, s);
      const dvec3 t_hat = t - u * glm::dot(u, t);
      return -(t_x_u * (glm::dot(s_hat, g) / alpha_t) + u_x_s * (glm::dot(t_hat, g) / alpha_s)) /
             det;
    }
    // Lines (nearly) coplanar with the view ray: the vertex moves like a point on them.
    return -g_tangent / glm::length(v.position - r);
  }
  const double alpha = glm::length(v.anchor - r);
  return alpha > 0.0 ? -g_tangent / alpha : dvec3(0.0);
}

}  // namespace

FormFactorGradient form_factor_gradient(const dvec3& r, const dvec3& n,
                                        std::span<const ContourVertex> contour) {
  if (contour.size() < 3 || !receiver_in_front(r, contour)) return {};
  return finite_or_zero(with_horizon_clip(r, n, contour, [&](std::span<const ContourVertex> poly) {
    // Arvo's vertex-Jacobian form: grad F = 1/2pi sum_k J_k^T g_k, with g_k the
    // derivative of the two edge terms touching vertex k with respect to u_k.
    const size_t size = poly.size();
    PolygonBuffer<dvec3> directions(size), dfdu(size);
    dvec3* u = directions.data();
    dvec3* g = dfdu.data();
    for (size_t k = 0; k < size; ++k) {
      u[k] = poly[k].position - r;
      const double length = glm::length(u[k]);
      u[k] = length > 0.0 ? u[k] / length : dvec3(0.0);
      g[k] = dvec3(0.0);
    }
    FormFactorGradient result;
    for (size_t i = 0; i < size; ++i) {
      const size_t j = (i + 1) % size;
      const dvec3 pi = poly[i].position - r;
      const dvec3 pj = poly[j].position - r;
      const EdgeTerm t = edge_term(poly[i].position, poly[j].position, pi, pj);
      if (!(t.s > 0.0)) continue;
      // Clockwise edge (a, b) = (u_j, u_i): sigma and kappa come from the precise
      // c and d, scaled to unit vectors, so tiny emitters keep their precision.
      const double scale = 1.0 / (glm::length(pi) * glm::length(pj));
      const double sigma = t.s * scale;
      const double kappa = t.d * scale;
      const dvec3 gamma = t.c / t.s;
      const double n_gamma = glm::dot(n, gamma);
      const dvec3 n_perp = n - n_gamma * gamma;
      const dvec3& a = u[j];
      const dvec3& b = u[i];
      g[j] += (-n_gamma * (b - kappa * a) + t.theta * glm::cross(b, n_perp)) / sigma;
      g[i] += (-n_gamma * (a - kappa * b) + t.theta * glm::cross(n_perp, a)) / sigma;
      result.value += t.theta * n_gamma;
    }
    for (size_t k = 0; k < size; ++k) {
      result.gradient += vertex_jacobian_transpose_times(poly[k], r, n, u[k], g[k]);
    }
    result.value *= kInvTwoPi;
    result.gradient *= kInvTwoPi;
    return result;
  }));
}

}  // namespace radiosity
