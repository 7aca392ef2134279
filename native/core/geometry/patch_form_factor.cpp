#include "core/geometry/patch_form_factor.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "core/geometry/form_factor.h"
#include "core/geometry/polygon.h"

namespace radiosity {
namespace {

constexpr size_t kMaxVertices = 16;
// A plane clip of a convex polygon adds at most one vertex; room for twice as
// many keeps slightly non-convex input from overflowing.
constexpr size_t kCapacity = 2 * kMaxVertices;

// Vertices relative to the polygon's own first input vertex: clipping and
// quadrature then round relative to the polygon's size, not to its offset.
struct Polygon {
  dvec3 origin{0.0};
  std::array<dvec3, kCapacity> v;
  size_t n = 0;
  std::span<const dvec3> view() const { return {v.data(), n}; }
  // The vertices in the frame of `frame` (its origin).
  Polygon in_frame_of(const Polygon& frame) const {
    Polygon moved = *this;
    moved.origin = frame.origin;
    const dvec3 shift = origin - frame.origin;
    for (size_t i = 0; i < n; ++i) moved.v[i] = shift + v[i];
    return moved;
  }
};

struct Plane {
  dvec3 normal{0.0};  // unit, zero for a degenerate polygon
  dvec3 point{0.0};
  double twice_area = 0.0;
  double size = 0.0;  // largest distance from `point` to a vertex
};

// Normal from edges relative to v0, which keeps tiny distant polygons precise.
Plane plane_of(std::span<const dvec3> polygon) {
  Plane plane;
  plane.point = polygon[0];
  const dvec3 area_normal = twice_area_normal(polygon);
  for (size_t i = 1; i < polygon.size(); ++i) {
    plane.size = std::max(plane.size, glm::length(polygon[i] - polygon[0]));
  }
  plane.twice_area = glm::length(area_normal);
  if (plane.twice_area > 0.0) plane.normal = area_normal / plane.twice_area;
  return plane;
}

double twice_area(std::span<const dvec3> polygon) { return plane_of(polygon).twice_area; }

// Height of x above the plane; zero within a tiny fraction of the clipped
// polygon's size and the rounding of the normal, so touching and coplanar
// polygons are recognised at any scale. Only differences of the input enter,
// so an offset changes nothing beyond the rounding of the input itself.
double height(const Plane& plane, const dvec3& x, double size) {
  const dvec3 d = x - plane.point;
  const double h = glm::dot(plane.normal, d);
  const double tolerance = 1e-12 * size + 1e-15 * glm::length(d);
  return std::abs(h) <= tolerance ? 0.0 : h;
}

// Sutherland-Hodgman clip to the plane's closed front half-space. False when no
// vertex lies strictly in front (behind or on the plane: nothing faces).
bool clip_to_front(std::span<const dvec3> in, const Plane& plane, double size, Polygon& out) {
  std::array<double, kCapacity> h{};
  if (in.size() > kCapacity) return false;
  bool any_front = false;
  for (size_t i = 0; i < in.size(); ++i) {
    h[i] = height(plane, in[i], size);
    any_front |= h[i] > 0.0;
  }
  if (!any_front) return false;
  out.origin = in[0];
  out.n = 0;
  for (size_t i = 0; i < in.size() && out.n + 2 <= kCapacity; ++i) {
    const size_t j = (i + 1) % in.size();
    const dvec3 a = in[i] - out.origin, b = in[j] - out.origin;
    if (h[i] >= 0.0) out.v[out.n++] = a;
    if ((h[i] > 0.0 && h[j] < 0.0) || (h[i] < 0.0 && h[j] > 0.0)) {
      out.v[out.n++] = a + (h[i] / (h[i] - h[j])) * (b - a);
    }
  }
  return out.n >= 3;
}

// ---- Quadrature rules ------------------------------------------------------------

// Gauss-Legendre nodes and weights on [0, 1], by Newton's method on P_n.
constexpr int kMaxGauss = 24;
struct GaussRule {
  std::array<double, kMaxGauss> x{}, w{};
};

const GaussRule& gauss_rule(int n) {
  static const std::array<GaussRule, kMaxGauss + 1> rules = [] {
    std::array<GaussRule, kMaxGauss + 1> all{};
    for (int m = 1; m <= kMaxGauss; ++m) {
      for (int i = 0; i < m; ++i) {
        double z = std::cos(kPi * (i + 0.75) / (m + 0.5));
        double derivative = 1.0;
        for (int iteration = 0; iteration < 100; ++iteration) {
          double p0 = 1.0, p1 = z;
          for (int k = 2; k <= m; ++k) {
            const double p2 = ((2 * k - 1) * z * p1 - (k - 1) * p0) / k;
            p0 = p1;
            p1 = p2;
          }
          derivative = m * (z * p1 - p0) / (z * z - 1.0);
          const double step = p1 / derivative;
          z -= step;
          if (std::abs(step) < 1e-16) break;
        }
        all[m].x[i] = 0.5 * (1.0 - z);
        all[m].w[i] = 1.0 / ((1.0 - z * z) * derivative * derivative);  // (2/...) * 1/2
      }
    }
    return all;
  }();
  return rules[std::clamp(n, 1, kMaxGauss)];
}

// Gauss-Kronrod 7-15 on [-1, 1] (nodes x >= 0; the Gauss nodes are the odd ones).
constexpr std::array<double, 8> kKronrodX = {
    0.991455371120812639206854697526329, 0.949107912342758524526189684047851,
    0.864864423359769072789712788640926, 0.741531185599394439863864773280788,
    0.586087235467691130294144845693013, 0.405845151377397166906606412076961,
    0.207784955007898467600689403773245, 0.0};
constexpr std::array<double, 8> kKronrodW = {
    0.022935322010529224963732008058970, 0.063092092629978553290700663189204,
    0.104790010322250183839876322541518, 0.140653259715525918745189590510238,
    0.169004726639267902826583426598550, 0.190350578064785409913256402421014,
    0.204432940075298892414161999234649, 0.209482141084727828012999174891714};
constexpr std::array<double, 4> kGauss7W = {
    0.129484966168869693270611432679082, 0.279705391489276667901467771423780,
    0.381830050505118944950369775488975, 0.417959183673469387755102040816327};

// |K15 - G7| measures G7's error, far above K15's on smooth integrands; the
// QUADPACK scaling (200 |K - G| / scale)^1.5 estimates K15's own. `splits`
// bounds the subdivisions of one integral: where the integrand's rounding
// exceeds the tolerance (a face 1e-12 of its neighbour's size: f's own terms
// cancel to 1 %), every interval would split down to depth 40, 2^40 of them.
constexpr int kMaxSplits = 4096;
template <class F>
double gauss_kronrod(const F& f, double a, double b, double scale, double tolerance, int depth,
                     int& splits) {
  const double mid = 0.5 * (a + b), half = 0.5 * (b - a);
  double kronrod = kKronrodW[7] * f(mid), gauss = kGauss7W[3] * f(mid);
  for (int i = 0; i < 7; ++i) {
    const double sum = f(mid - half * kKronrodX[i]) + f(mid + half * kKronrodX[i]);
    kronrod += kKronrodW[i] * sum;
    if (i % 2 == 1) gauss += kGauss7W[i / 2] * sum;
  }
  const double error = scale * std::pow(200.0 * std::abs(kronrod - gauss) * half / scale, 1.5);
  if (error <= tolerance || depth >= 40 || splits <= 0) return kronrod * half;
  --splits;
  return gauss_kronrod(f, a, mid, 0.5 * scale, 0.5 * tolerance, depth + 1, splits) +
         gauss_kronrod(f, mid, b, 0.5 * scale, 0.5 * tolerance, depth + 1, splits);
}

// Tanh-sinh nodes t = k h on [0, 3.5] for h = 1/2 at level 0, and the new (odd k)
// nodes of each halving of h. Each stores the weight (pi/2) cosh t / cosh^2 u and
// 1 - tanh u, u = (pi/2) sinh t: the abscissa measured from its endpoint, exact
// where the integrand's derivative is singular.
constexpr int kTanhSinhLevels = 7;
struct TanhSinhNode {
  double weight, offset;
};
struct TanhSinhRule {
  std::array<std::array<TanhSinhNode, 512>, kTanhSinhLevels> nodes{};
  std::array<int, kTanhSinhLevels> count{};
};

const TanhSinhRule& tanh_sinh_rule() {
  static const TanhSinhRule rule = [] {
    TanhSinhRule r;
    for (int level = 0; level < kTanhSinhLevels; ++level) {
      const double h = 0.5 / (1 << level);
      for (int k = 1; k * h <= 3.5; k += level == 0 ? 1 : 2) {
        const double t = k * h, u = 0.5 * kPi * std::sinh(t);
        const double cu = std::cosh(u);
        r.nodes[level][r.count[level]++] = {0.5 * kPi * std::cosh(t) / (cu * cu),
                                            2.0 / (1.0 + std::exp(2.0 * u))};
      }
    }
    return r;
  }();
  return rule;
}

// Stops when a halving of h changes the sum by less than `tolerance`: the error
// then is of the order of that change squared (double-exponential convergence).
template <class F>
double tanh_sinh(const F& f, double a, double b, double tolerance) {
  const TanhSinhRule& rule = tanh_sinh_rule();
  const double half = 0.5 * (b - a);
  double sum = 0.5 * kPi * f(a + half), estimate = 0.0;
  for (int level = 0; level < kTanhSinhLevels; ++level) {
    for (int k = 0; k < rule.count[level]; ++k) {
      const TanhSinhNode& node = rule.nodes[level][k];
      const double d = half * node.offset;
      sum += node.weight * (f(a + d) + f(b - d));
    }
    const double next = sum * half * (0.5 / (1 << level));
    if (level >= 2 && std::abs(next - estimate) <= tolerance) return next;
    estimate = next;
  }
  return estimate;
}

// ---- Contour form (near pairs) ---------------------------------------------------

struct Edge {
  dvec3 start;
  dvec3 unit;
  double length;
};

// Edges in local coordinates (x - origin) * inv_scale; vanishing edges dropped.
size_t edges_of(const Polygon& polygon, const dvec3& origin, double inv_scale,
                std::array<Edge, kCapacity>& edges) {
  size_t count = 0;
  for (size_t i = 0; i < polygon.n; ++i) {
    const dvec3 a = (polygon.v[i] - origin) * inv_scale;
    const dvec3 b = (polygon.v[(i + 1) % polygon.n] - origin) * inv_scale;
    const double length = glm::length(b - a);
    if (length > 1e-14) edges[count++] = {a, (b - a) / length, length};
  }
  return count;
}

double half_tau_log(double tau, double h2) {
  const double r2 = tau * tau + h2;
  return r2 > 0.0 ? 0.5 * tau * std::log(r2) : 0.0;  // the limit tau ln|tau| -> 0
}

// Integral over edge e of ln|x - y| dy, without its constant term -length (which
// sums to zero over closed contours): with tau = t - t0 and h the distance from
// x to the edge's line, [tau ln(tau^2 + h^2) / 2 + h atan(tau / h)].
double log_distance_integral(const dvec3& x, const Edge& e) {
  const dvec3 w = x - e.start;
  const double t0 = glm::dot(w, e.unit);
  const double h = glm::length(glm::cross(w, e.unit));
  const double a = -t0, b = e.length - t0;
  // atan(b / h) - atan(a / h) in one call, in [0, pi), 0 when h = 0.
  return half_tau_log(b, h * h) - half_tau_log(a, h * h) +
         h * std::atan2(h * e.length, h * h + a * b);
}

double distance_to_segment(const dvec3& x, const Edge& e) {
  const dvec3 w = x - e.start;
  const double t = std::clamp(glm::dot(w, e.unit), 0.0, e.length);
  return glm::length(w - t * e.unit);
}

// int over edge i of int over edge j of ln r, both by arc length, split where
// the integrand may be non-smooth: where edge i passes the ends of edge j and
// where the two lines come closest.
double edge_pair_integral(const Edge& ei, const Edge& ej) {
  std::array<double, 5> cuts{};
  size_t count = 0;
  cuts[count++] = 0.0;
  auto add = [&](double s) {
    if (s > 1e-12 * ei.length && s < ei.length * (1 - 1e-12)) cuts[count++] = s;
  };
  add(glm::dot(ej.start - ei.start, ei.unit));
  add(glm::dot(ej.start + ej.length * ej.unit - ei.start, ei.unit));
  const double c = glm::dot(ei.unit, ej.unit);
  if (1.0 - c * c > 1e-12) {
    const dvec3 w0 = ei.start - ej.start;
    add((c * glm::dot(ej.unit, w0) - glm::dot(ei.unit, w0)) / (1.0 - c * c));
  }
  for (size_t k = 2; k < count; ++k) {  // at most three cuts: insertion sort
    for (size_t m = k; m > 1 && cuts[m] < cuts[m - 1]; --m) std::swap(cuts[m], cuts[m - 1]);
  }
  cuts[count++] = ei.length;

  const auto f = [&](double s) { return log_distance_integral(ei.start + s * ei.unit, ej); };
  double total = 0.0;
  for (size_t k = 0; k + 1 < count; ++k) {
    const double a = cuts[k], b = cuts[k + 1];
    const double span = b - a;
    if (span <= 1e-13 * ei.length) continue;
    const double tolerance = 1e-14 * span * std::max(ej.length, 1e-3);
    const bool near_end = distance_to_segment(ei.start + a * ei.unit, ej) < 0.25 * span ||
                          distance_to_segment(ei.start + b * ei.unit, ej) < 0.25 * span;
    int splits = kMaxSplits;
    total += near_end ? tanh_sinh(f, a, b, 1e-10 * span * ej.length)
                      : gauss_kronrod(f, a, b, span * ej.length, tolerance, 0, splits);
  }
  return total;
}

// A_p F_pq by the contour form, for polygons already clipped to each other.
double contour_form(const Polygon& p, const Polygon& q_own_frame) {
  const Polygon q = q_own_frame.in_frame_of(p);
  // Local origin and a power-of-two scale: rounding-free rescaling to O(1).
  dvec3 low = p.v[0], high = p.v[0];
  for (const Polygon* polygon : {&p, &q}) {
    for (size_t i = 0; i < polygon->n; ++i) {
      low = glm::min(low, polygon->v[i]);
      high = glm::max(high, polygon->v[i]);
    }
  }
  const dvec3 origin = 0.5 * (low + high);
  int exponent = 0;
  std::frexp(glm::length(high - low), &exponent);
  const double scale = std::ldexp(1.0, exponent);
  std::array<Edge, kCapacity> ep, eq;
  const size_t np = edges_of(p, origin, 1.0 / scale, ep);
  const size_t nq = edges_of(q, origin, 1.0 / scale, eq);
  double sum = 0.0;
  for (size_t i = 0; i < np; ++i) {
    for (size_t j = 0; j < nq; ++j) {
      const double c = glm::dot(ep[i].unit, eq[j].unit);
      if (std::abs(c) > 1e-15) sum += c * edge_pair_integral(ep[i], eq[j]);
    }
  }
  return std::max(0.0, sum * kInvTwoPi) * scale * scale;
}

// ---- Point-kernel quadrature (far pairs) -----------------------------------------

// A_s F_so: Gauss quadrature of the point kernel over `s`, fan triangles mapped
// from the unit square (Duffy), `order` points per direction.
double point_kernel_quadrature(const Polygon& s, const dvec3& normal, const Polygon& o_own_frame,
                               int order) {
  const Polygon o = o_own_frame.in_frame_of(s);
  const GaussRule& rule = gauss_rule(order);
  double total = 0.0;
  if (s.n == 4) {  // a quad maps bilinearly from the square: half the points of two triangles
    const dvec3 &a = s.v[0], &b = s.v[1], &c = s.v[2], &d = s.v[3];
    for (int i = 0; i < order; ++i) {
      const double u = rule.x[i];
      for (int j = 0; j < order; ++j) {
        const double v = rule.x[j];
        const dvec3 x = (1 - u) * ((1 - v) * a + v * d) + u * ((1 - v) * b + v * c);
        const dvec3 du = (1 - v) * (b - a) + v * (c - d), dv = (1 - u) * (d - a) + u * (c - b);
        total += rule.w[i] * rule.w[j] * glm::length(glm::cross(du, dv)) *
                 form_factor(x, normal, o.view());
      }
    }
    return total;
  }
  for (size_t k = 1; k + 1 < s.n; ++k) {
    const dvec3 e1 = s.v[k] - s.v[0], e2 = s.v[k + 1] - s.v[0];
    const double jacobian = glm::length(glm::cross(e1, e2));
    double triangle = 0.0;
    for (int i = 0; i < order; ++i) {
      const double u = rule.x[i];
      for (int j = 0; j < order; ++j) {
        const double v = rule.x[j];
        const dvec3 x = s.v[0] + u * ((1.0 - v) * e1 + v * e2);
        triangle += rule.w[i] * rule.w[j] * u * form_factor(x, normal, o.view());
      }
    }
    total += jacobian * triangle;
  }
  return total;
}

struct Ball {
  dvec3 centre{0.0};
  double radius = 0.0;
};

Ball bounding_ball(const Polygon& polygon) {
  Ball ball;
  for (size_t i = 0; i < polygon.n; ++i) ball.centre += polygon.v[i];
  ball.centre /= static_cast<double>(polygon.n);
  for (size_t i = 0; i < polygon.n; ++i) {
    ball.radius = std::max(ball.radius, glm::length(polygon.v[i] - ball.centre));
  }
  ball.centre += polygon.origin;
  return ball;
}

// Gauss order for the point kernel over a polygon whose bounding ball is
// `delta` of its radii from the other polygon. Error of n-point Gauss ~
// rho^(-2n), rho the Bernstein ellipse reaching the nearest singularity (the
// other polygon): rho^(-2n) < tolerance, and one order more (measured: 1e-13
// at delta = 3 for 1e-12).
int far_order(double delta, double tolerance) {
  const double rho = delta + std::sqrt(delta * delta + 1.0);
  const double digits = -std::log(std::clamp(tolerance, 1e-15, 1e-2));
  return std::clamp(static_cast<int>(std::ceil(0.5 * digits / std::log(rho))) + 1, 2, kMaxGauss);
}

// Far pairs (gap of at least this many radii of the smaller polygon) take the
// point kernel's quadrature; near pairs whose radii differ by more than
// kLopsided have the larger polygon cut around the smaller one first: the
// contour form sums terms of the larger size down to a result of the
// smaller's and loses digits in proportion (a 1.5e-14 polygon resting on the
// plane of a 0.25 one gave F = 3.5e12, fuzzing).
constexpr double kFarGap = 3.0;
constexpr double kLopsided = 8.0;

Polygon clipped(const Polygon& polygon, const dvec3& normal, const dvec3& point, double size,
                bool& any) {
  std::array<dvec3, kCapacity> absolute;
  for (size_t i = 0; i < polygon.n; ++i) absolute[i] = polygon.origin + polygon.v[i];
  Plane plane;
  plane.normal = normal;
  plane.point = point;
  Polygon out;
  any = clip_to_front({absolute.data(), polygon.n}, plane, size, out);
  return out;
}

// A_a F_ab = A_b F_ba of two clipped polygons facing each other.
double exchange(const Polygon& a, const Plane& plane_a, const Polygon& b, const Plane& plane_b,
                double tolerance) {
  const Ball ball_a = bounding_ball(a), ball_b = bounding_ball(b);
  const double gap = glm::length(ball_a.centre - ball_b.centre) - ball_a.radius - ball_b.radius;
  const bool a_smaller = ball_a.radius <= ball_b.radius;
  const Polygon& small = a_smaller ? a : b;
  const Polygon& large = a_smaller ? b : a;
  const Plane& small_plane = a_smaller ? plane_a : plane_b;
  const Plane& large_plane = a_smaller ? plane_b : plane_a;
  const double r = std::min(ball_a.radius, ball_b.radius),
               big = std::max(ball_a.radius, ball_b.radius);
  if (gap >= kFarGap * r)
    return point_kernel_quadrature(small, small_plane.normal, large, far_order(gap / r, tolerance));
  if (big <= kLopsided * r) return contour_form(a, b);
  // The large polygon in pieces: four beyond the sides of a square of
  // half-width (kFarGap + 1) r about the small one's centre (in the large
  // one's plane), each at least kFarGap r from the small one, and the square's
  // part, no longer lopsided.
  const dvec3 n = large_plane.normal;
  const dvec3 centre = (a_smaller ? ball_a : ball_b).centre;
  const dvec3 c = centre - glm::dot(n, centre - large_plane.point) * n;
  const dvec3 helper = std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 u = glm::normalize(glm::cross(helper, n)), v = glm::cross(n, u);
  const double w = (kFarGap + 1.0) * r;
  const int order = far_order(kFarGap, tolerance);
  double total = 0.0;
  Polygon near = large;
  for (const dvec3& axis : {u, -u, v, -v}) {
    bool any = false;
    const Polygon beyond = clipped(near, axis, c + w * axis, large_plane.size, any);
    if (any) total += point_kernel_quadrature(small, small_plane.normal, beyond, order);
    near = clipped(near, -axis, c + w * axis, large_plane.size, any);
    if (!any) return total;
  }
  return total + contour_form(a_smaller ? small : near, a_smaller ? near : small);
}

bool finite(std::span<const dvec3> polygon) {
  for (const dvec3& v : polygon) {
    if (!std::isfinite(v.x) || !std::isfinite(v.y) || !std::isfinite(v.z)) return false;
  }
  return true;
}

}  // namespace

double patch_form_factor(std::span<const dvec3> p, std::span<const dvec3> q, double tolerance) {
  if (p.size() > kMaxVertices || q.size() > kMaxVertices) {
    throw std::invalid_argument("patch_form_factor: more than 16 vertices");
  }
  if (p.size() < 3 || q.size() < 3 || !finite(p) || !finite(q)) return 0.0;
  const Plane plane_p = plane_of(p), plane_q = plane_of(q);
  if (!(plane_p.twice_area > 0.0) || !(plane_q.twice_area > 0.0)) return 0.0;

  Polygon pc, qc;
  if (!clip_to_front(p, plane_q, plane_p.size, pc) ||
      !clip_to_front(q, plane_p, plane_q.size, qc)) {
    return 0.0;
  }
  // Slivers left by clipping carry no measurable exchange.
  if (twice_area(pc.view()) <= 1e-14 * plane_p.twice_area ||
      twice_area(qc.view()) <= 1e-14 * plane_q.twice_area) {
    return 0.0;
  }

  return exchange(pc, plane_p, qc, plane_q, tolerance) / (0.5 * plane_p.twice_area);
}

}  // namespace radiosity
