// Visible polygon of an emitter (Section 4.3): see visible_polygon.h for the method.
#include "core/visible_polygon.h"

#include <algorithm>
#include <cmath>

namespace radiosity {
namespace {

// The 3D line that generates an edge of a polygon on the emitter plane.
struct EdgeLine {
  Line line;
  // The line lies in the emitter plane (emitter edge, trace of an occluder plane,
  // horizon): it is its own projection, fixed when the receiver moves.
  bool on_emitter_plane = false;
  // The receiver's horizon: the cosine at the receiver vanishes along it, so
  // vertices on it act as fixed vertices (MATH.md section 2).
  bool horizon = false;
};

// Orthonormal frame of the emitter plane, e1 x e2 = front normal, so that
// counter-clockwise in 2D is counter-clockwise about the front normal.
struct EmitterFrame {
  dvec3 origin{0.0}, e1{0.0}, e2{0.0}, normal{0.0};

  dvec2 to_plane(const dvec3& p) const {
    const dvec3 d = p - origin;
    return {glm::dot(d, e1), glm::dot(d, e2)};
  }
  dvec3 to_space(const dvec2& q) const { return origin + q.x * e1 + q.y * e2; }
  double height(const dvec3& p) const { return glm::dot(normal, p - origin); }
};

// A convex polygon on the emitter plane: 2D positions (for clipping), contour
// vertices (for F and its gradient), and per edge i (vertex i to i+1) its line.
struct PlanePolygon {
  std::vector<dvec2> p;
  std::vector<ContourVertex> v;
  std::vector<EdgeLine> edge;

  std::size_t size() const { return p.size(); }
  void clear() {
    p.clear();
    v.clear();
    edge.clear();
  }
  void push(const dvec2& q, const ContourVertex& cv, const EdgeLine& out) {
    p.push_back(q);
    v.push_back(cv);
    edge.push_back(out);
  }
};

// A half-plane w . q + c >= 0 on the emitter plane, |w| = 1, with the line that
// generates its boundary.
struct HalfPlane {
  dvec2 w{0.0};
  double c = 0.0;
  EdgeLine boundary;
  double distance(const dvec2& q) const { return glm::dot(w, q) + c; }
};

double cross2(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }

double signed_area(const std::vector<dvec2>& p) {
  double a = 0.0;
  for (std::size_t i = 0, k = p.size(); i < k; ++i) a += cross2(p[i], p[(i + 1) % k]);
  return 0.5 * a;
}

struct Tolerances {
  double plane = 0.0;  // lengths on the emitter plane (2D clipping)
  double space = 0.0;  // lengths in 3D (occluder clipping, line distances)
  double area = 0.0;   // pieces smaller than this are dropped
};

// The vertex where edges `a` (incoming) and `b` (outgoing) meet, at `pos` on the
// emitter plane, seen from `r`.
ContourVertex crossing_vertex(const EdgeLine& a, const EdgeLine& b, const dvec3& pos,
                              const dvec3& r, const Tolerances& tol) {
  // Both lines on the emitter plane (emitter vertex, trace x emitter edge), or the
  // horizon involved (fixed vertex, MATH.md section 2): a fixed point of the plane.
  if (a.horizon || b.horizon || (a.on_emitter_plane && b.on_emitter_plane))
    return ContourVertex::intrinsic(pos);
  const dvec3 d1 = a.line.direction, d2 = b.line.direction;
  const dvec3 c = glm::cross(d1, d2);
  const double cc = glm::dot(c, c);
  if (cc <= 1e-24 * glm::dot(d1, d1) * glm::dot(d2, d2)) {
    // Parallel 3D lines: their projections meet at the vanishing point, whose
    // direction from r does not change as r moves (vertex Jacobian 0, the limit of
    // eq. 15 as the distance grows). A far anchor along the same ray says so.
    return ContourVertex::intrinsic(pos, r + (pos - r) * 1e9);
  }
  const dvec3 w = b.line.point - a.line.point;
  const double dist = std::abs(glm::dot(w, c)) / std::sqrt(cc);
  if (dist <= tol.space) {
    // The lines meet in 3D: a real vertex (an occluder vertex, a shared mesh vertex,
    // or an occluder edge piercing the emitter plane), eq. 15 at its 3D position.
    const double t1 = glm::dot(glm::cross(w, d2), c) / cc;
    return ContourVertex::intrinsic(pos, a.line.point + t1 * d1);
  }
  // Two skew lines crossing only as seen from r: an apparent vertex (eq. 14).
  return ContourVertex::apparent_vertex(pos, a.line, b.line);
}

// Keeps the part of `in` where the half-plane distance has sign `side` (+1 inside,
// -1 outside), Sutherland-Hodgman with the vertices within `tol.plane` of the
// line counted on both sides. New edges along the boundary take its line; new
// vertices are the crossing of the cut edge and the boundary.
void clip_polygon(const PlanePolygon& in, const std::vector<double>& dist, int side,
                  const HalfPlane& h, const EmitterFrame& frame, const dvec3& r,
                  const Tolerances& tol, PlanePolygon& out) {
  out.clear();
  const std::size_t k = in.size();
  const auto cls = [&](std::size_t i) {
    const double s = side * dist[i];
    return s > tol.plane ? 1 : (s < -tol.plane ? -1 : 0);
  };
  for (std::size_t i = 0; i < k; ++i) {
    const std::size_t j = (i + 1) % k;
    const int ci = cls(i), cj = cls(j);
    if (ci >= 0) {
      if (cj >= 0) {
        out.push(in.p[i], in.v[i], in.edge[i]);
      } else if (ci == 0) {
        out.push(in.p[i], in.v[i], h.boundary);  // leaves along the boundary
      } else {
        out.push(in.p[i], in.v[i], in.edge[i]);
        const double t = dist[i] / (dist[i] - dist[j]);
        const dvec2 q = in.p[i] + t * (in.p[j] - in.p[i]);
        out.push(q, crossing_vertex(in.edge[i], h.boundary, frame.to_space(q), r, tol),
                 h.boundary);
      }
    } else if (cj > 0) {
      const double t = dist[i] / (dist[i] - dist[j]);
      const dvec2 q = in.p[i] + t * (in.p[j] - in.p[i]);
      out.push(q, crossing_vertex(h.boundary, in.edge[i], frame.to_space(q), r, tol),
               in.edge[i]);
    }
  }
}

// Removes consecutive vertices closer than the tolerance (the edge between them
// has no length; the survivor keeps the later outgoing edge) and reports whether
// a polygon of positive area is left.
bool clean_polygon(PlanePolygon& poly, const Tolerances& tol) {
  if (poly.size() < 3) return false;
  PlanePolygon out;
  for (std::size_t i = 0; i < poly.size(); ++i) {
    if (!out.p.empty() && glm::length(poly.p[i] - out.p.back()) <= tol.plane) {
      out.edge.back() = poly.edge[i];
      continue;
    }
    out.push(poly.p[i], poly.v[i], poly.edge[i]);
  }
  while (out.size() >= 2 && glm::length(out.p.front() - out.p.back()) <= tol.plane) {
    out.p.pop_back();
    out.v.pop_back();
    out.edge.pop_back();
  }
  if (out.size() < 3 || signed_area(out.p) <= tol.area) return false;
  poly = std::move(out);
  return true;
}

// Half-planes bounding a convex counter-clockwise polygon: inside to the left of
// each edge.
HalfPlane edge_half_plane(const PlanePolygon& poly, std::size_t i) {
  const dvec2 a = poly.p[i], b = poly.p[(i + 1) % poly.size()];
  const dvec2 d = glm::normalize(b - a);
  HalfPlane h;
  h.w = {-d.y, d.x};
  h.c = -glm::dot(h.w, a);
  h.boundary = poly.edge[i];
  return h;
}

// Separating-axis test for two convex polygons: true when they share no interior.
bool disjoint(const PlanePolygon& a, const PlanePolygon& b, const Tolerances& tol) {
  const auto separated_by_edges_of = [&](const PlanePolygon& p, const PlanePolygon& q) {
    for (std::size_t i = 0; i < p.size(); ++i) {
      const HalfPlane h = edge_half_plane(p, i);
      bool all_outside = true;
      for (const dvec2& x : q.p)
        if (h.distance(x) > tol.plane) {
          all_outside = false;
          break;
        }
      if (all_outside) return true;
    }
    return false;
  };
  return separated_by_edges_of(a, b) || separated_by_edges_of(b, a);
}

// Emitter frame from the polygon (normal from edges relative to v0, MATH.md 1).
EmitterFrame make_frame(std::span<const dvec3> emitter) {
  EmitterFrame f;
  f.origin = emitter[0];
  dvec3 nsum(0.0);
  for (std::size_t i = 1; i + 1 < emitter.size(); ++i)
    nsum += glm::cross(emitter[i] - emitter[0], emitter[i + 1] - emitter[0]);
  f.normal = glm::normalize(nsum);
  // e1 along the first edge; e2 completes a right-handed frame.
  dvec3 e = emitter[1] - emitter[0];
  e -= glm::dot(e, f.normal) * f.normal;
  f.e1 = glm::normalize(e);
  f.e2 = glm::cross(f.normal, f.e1);
  return f;
}

double diameter(std::span<const dvec3> poly) {
  double d = 0.0;
  for (std::size_t i = 0; i < poly.size(); ++i)
    for (std::size_t j = i + 1; j < poly.size(); ++j) d = std::max(d, glm::length(poly[i] - poly[j]));
  return d;
}

// A polygon in 3D during occluder clipping: vertex positions, whether each is an
// original occluder vertex, and the line of each outgoing edge.
struct SpacePolygon {
  std::vector<dvec3> x;
  std::vector<bool> original;
  std::vector<EdgeLine> edge;
  std::size_t size() const { return x.size(); }
};

// Clips a 3D convex polygon to m . (x - o) >= 0 (points within tol count as in).
void clip_space(const SpacePolygon& in, const dvec3& m, const dvec3& o, const EdgeLine& boundary,
                double tol, SpacePolygon& out) {
  out.x.clear();
  out.original.clear();
  out.edge.clear();
  const std::size_t k = in.size();
  std::vector<double> d(k);
  for (std::size_t i = 0; i < k; ++i) d[i] = glm::dot(m, in.x[i] - o);
  const auto cls = [&](std::size_t i) { return d[i] > tol ? 1 : (d[i] < -tol ? -1 : 0); };
  const auto push = [&](const dvec3& x, bool orig, const EdgeLine& e) {
    out.x.push_back(x);
    out.original.push_back(orig);
    out.edge.push_back(e);
  };
  for (std::size_t i = 0; i < k; ++i) {
    const std::size_t j = (i + 1) % k;
    const int ci = cls(i), cj = cls(j);
    if (ci >= 0) {
      if (cj >= 0) {
        push(in.x[i], in.original[i], in.edge[i]);
      } else if (ci == 0) {
        push(in.x[i], in.original[i], boundary);
      } else {
        push(in.x[i], in.original[i], in.edge[i]);
        push(in.x[i] + (d[i] / (d[i] - d[j])) * (in.x[j] - in.x[i]), false, boundary);
      }
    } else if (cj > 0) {
      push(in.x[i] + (d[i] / (d[i] - d[j])) * (in.x[j] - in.x[i]), false, in.edge[i]);
    }
  }
}

struct Setup {
  EmitterFrame frame;
  Tolerances tol;
  double height_r = 0.0;          // receiver height above the emitter plane
  PlanePolygon emitter;            // horizon-clipped emitter, 2D
  std::vector<dvec3> corners;      // its corners in 3D
};

// Projects occluder `tri` from r onto the emitter plane, clipped to the pyramid
// from r through the (horizon-clipped) emitter. Returns false if nothing of
// positive area remains.
bool project_occluder(const Triangle& tri, const dvec3& r, const Setup& s, PlanePolygon& q) {
  const EmitterFrame& f = s.frame;
  const double tol = s.tol.space;
  // Skip what cannot block: degenerate triangles, triangles whose plane holds r
  // (they project to a segment), triangles on or behind the emitter plane
  // (coplanar faces are the emitter's neighbours, not blockers).
  const dvec3 nt = glm::cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
  const double nt_len = glm::length(nt);
  if (!(nt_len > 0.0)) return false;
  const dvec3 nt_unit = nt / nt_len;
  if (std::abs(glm::dot(nt_unit, r - tri.v[0])) <= tol) return false;
  double hmax = -1.0;
  for (const dvec3& x : tri.v) hmax = std::max(hmax, f.height(x));
  if (hmax <= tol) return false;

  SpacePolygon poly, tmp;
  for (int i = 0; i < 3; ++i) {
    const dvec3 a = tri.v[i], b = tri.v[(i + 1) % 3];
    const bool planar = std::abs(f.height(a)) <= tol && std::abs(f.height(b)) <= tol;
    poly.x.push_back(a);
    poly.original.push_back(true);
    poly.edge.push_back({Line{a, b - a}, planar, false});
  }

  // Side planes of the pyramid: through r and each edge of the emitter, normal
  // pointing inwards ((r - v_i) x e_i, vertices counter-clockwise about the front).
  const std::size_t k = s.corners.size();
  for (std::size_t i = 0; i < k; ++i) {
    const dvec3 vi = s.corners[i], vj = s.corners[(i + 1) % k];
    dvec3 m = glm::cross(r - vi, vj - vi);
    const double ml = glm::length(m);
    if (!(ml > 0.0)) continue;
    m /= ml;
    // Quick reject: the whole triangle outside (or on) this side plane.
    bool all_out = true;
    for (const dvec3& x : tri.v)
      if (glm::dot(m, x - r) > tol) {
        all_out = false;
        break;
      }
    if (all_out) return false;
    clip_space(poly, m, r, s.emitter.edge[i], tol, tmp);
    std::swap(poly, tmp);
    if (poly.size() < 3) return false;
  }
  // Emitter plane: keep the part in front of it. The new edge is the trace of the
  // occluder's plane on the emitter plane.
  double hmin = 1e300;
  for (const dvec3& x : poly.x) hmin = std::min(hmin, f.height(x));
  if (hmin < -tol) {
    const dvec3 dir = glm::cross(nt_unit, f.normal);
    const double dd = glm::dot(dir, dir);
    EdgeLine trace;
    trace.on_emitter_plane = true;
    trace.line.direction = dir;
    if (dd > 1e-24) {
      const double h1 = glm::dot(nt_unit, tri.v[0]), h2 = glm::dot(f.normal, f.origin);
      trace.line.point = (h1 * glm::cross(f.normal, dir) + h2 * glm::cross(dir, nt_unit)) / dd;
    } else {
      trace.line.point = f.origin;
    }
    clip_space(poly, f.normal, f.origin, trace, tol, tmp);
    std::swap(poly, tmp);
    if (poly.size() < 3) return false;
  }

  // Central projection from r onto the emitter plane.
  const std::size_t m = poly.size();
  q.clear();
  for (std::size_t i = 0; i < m; ++i) {
    const dvec3& x = poly.x[i];
    const double depth = s.height_r - f.height(x);  // > 0 between r and the emitter
    if (!(depth > 0.0)) return false;                // only at r itself: plane through r
    const dvec3 pos = r + (x - r) * (s.height_r / depth);
    q.p.push_back(f.to_plane(pos));
    q.edge.push_back(poly.edge[i]);
    const EdgeLine& incoming = poly.edge[(i + m - 1) % m];
    q.v.push_back(poly.original[i] ? ContourVertex::intrinsic(f.to_space(q.p.back()), x)
                                   : crossing_vertex(incoming, poly.edge[i],
                                                     f.to_space(q.p.back()), r, s.tol));
  }
  // Counter-clockwise, like the pieces it is subtracted from.
  if (signed_area(q.p) < 0.0) {
    PlanePolygon rev;
    for (std::size_t i = 0; i < m; ++i) {
      const std::size_t a = m - 1 - i;              // vertex
      const std::size_t e = (2 * m - 2 - i) % m;    // edge from old a to old a-1
      rev.push(q.p[a], q.v[a], q.edge[e]);
    }
    q = std::move(rev);
  }
  return clean_polygon(q, s.tol);
}

// Subtracts convex `q` from every piece (successive half-planes, DESIGN.md 4).
void subtract(std::vector<PlanePolygon>& pieces, const PlanePolygon& q, const dvec3& r,
              const Setup& s, std::vector<PlanePolygon>& scratch) {
  scratch.clear();
  std::vector<HalfPlane> halves(q.size());
  for (std::size_t i = 0; i < q.size(); ++i) halves[i] = edge_half_plane(q, i);
  std::vector<double> dist;
  PlanePolygon inside, outside;
  for (PlanePolygon& piece : pieces) {
    if (disjoint(piece, q, s.tol)) {
      scratch.push_back(std::move(piece));
      continue;
    }
    PlanePolygon rest = std::move(piece);
    for (const HalfPlane& h : halves) {
      dist.resize(rest.size());
      bool any_out = false;
      for (std::size_t i = 0; i < rest.size(); ++i) {
        dist[i] = h.distance(rest.p[i]);
        any_out = any_out || dist[i] < -s.tol.plane;
      }
      if (!any_out) continue;  // the rest lies inside this half-plane: no cut
      clip_polygon(rest, dist, -1, h, s.frame, r, s.tol, outside);
      if (clean_polygon(outside, s.tol)) scratch.push_back(outside);
      clip_polygon(rest, dist, +1, h, s.frame, r, s.tol, inside);
      if (!clean_polygon(inside, s.tol)) {
        rest.clear();
        break;
      }
      rest = inside;
    }
    // What is left of the piece lies inside q: hidden.
  }
  std::swap(pieces, scratch);
}

// Builds the frame and tolerances and clips the emitter to the horizon. Returns
// false when the receiver cannot see the emitter's front at all.
bool make_setup(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter, Setup& s) {
  s.frame = make_frame(emitter);
  const double size = diameter(emitter);
  s.height_r = s.frame.height(r);
  // Receiver on or behind the emitter plane sees nothing (MATH.md section 3).
  // (same threshold as form_factor.cpp, so the two agree on what is visible).
  const double rounding = 1e-15 * (glm::length(r) + glm::length(s.frame.origin));
  if (!(s.height_r > 1e-12 * size + rounding)) return false;
  s.tol.plane = 1e-11 * size;
  s.tol.space = 1e-11 * std::max(size, glm::length(r - s.frame.origin));
  s.tol.area = 1e-22 * size * size;

  PlanePolygon poly;
  const std::size_t k = emitter.size();
  for (std::size_t i = 0; i < k; ++i) {
    const dvec3 a = emitter[i], b = emitter[(i + 1) % k];
    poly.push(s.frame.to_plane(a), ContourVertex::intrinsic(a), {Line{a, b - a}, true, false});
  }
  // Horizon: n . (x - r) >= 0 on the emitter plane is w . q + c >= 0.
  HalfPlane h;
  h.w = {glm::dot(n, s.frame.e1), glm::dot(n, s.frame.e2)};
  h.c = glm::dot(n, s.frame.origin - r);
  const double wl = glm::length(h.w);
  if (wl > 1e-12) {
    h.w /= wl;
    h.c /= wl;
    h.boundary.on_emitter_plane = true;
    h.boundary.horizon = true;
    h.boundary.line.direction = s.frame.to_space(dvec2(-h.w.y, h.w.x)) - s.frame.origin;
    h.boundary.line.point = s.frame.to_space(-h.c * h.w);
    std::vector<double> dist(poly.size());
    bool any_below = false;
    for (std::size_t i = 0; i < poly.size(); ++i) {
      dist[i] = h.distance(poly.p[i]);
      any_below = any_below || dist[i] < -s.tol.plane;
    }
    if (any_below) {
      PlanePolygon clipped;
      clip_polygon(poly, dist, +1, h, s.frame, r, s.tol, clipped);
      poly = std::move(clipped);
    }
  } else if (h.c <= 0.0) {
    return false;  // receiver plane parallel to the emitter, facing away
  }
  if (!clean_polygon(poly, s.tol)) return false;
  s.emitter = poly;
  s.corners.clear();
  for (const dvec2& q : s.emitter.p) s.corners.push_back(s.frame.to_space(q));
  return true;
}

}  // namespace

VisiblePolygon visible_polygon(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                               std::span<const Triangle> occluders) {
  VisiblePolygon out;
  Setup s;
  if (emitter.size() < 3 || !make_setup(r, n, emitter, s)) return out;
  std::vector<PlanePolygon> pieces{s.emitter}, scratch;
  PlanePolygon q;
  for (const Triangle& tri : occluders) {
    if (!project_occluder(tri, r, s, q)) continue;
    out.occluded = true;
    subtract(pieces, q, r, s, scratch);
    if (pieces.empty()) break;
  }
  out.pieces.reserve(pieces.size());
  for (PlanePolygon& p : pieces) out.pieces.push_back(std::move(p.v));
  return out;
}

FormFactorGradient visible_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                std::span<const Triangle> occluders) {
  const VisiblePolygon visible = visible_polygon(r, n, emitter, occluders);
  if (visible.empty()) return {};
  const FormFactorGradient unoccluded = form_factor_gradient(r, n, emitter);
  if (!visible.occluded) return unoccluded;
  FormFactorGradient sum;
  for (const VisiblePiece& piece : visible.pieces) {
    const FormFactorGradient fg = form_factor_gradient(r, n, std::span<const ContourVertex>(piece));
    sum.value += fg.value;
    sum.gradient += fg.gradient;
  }
  // Rounding can push the sum a hair outside [0, unoccluded F]; the pieces are a
  // subset of the emitter, so clamp there.
  // A non-finite sum would mean a vertex Jacobian blew up at an exact D1 event
  // (eq. 14 singular); the gradient is undefined there, F is not.
  if (!std::isfinite(sum.gradient.x) || !std::isfinite(sum.gradient.y) ||
      !std::isfinite(sum.gradient.z))
    sum.gradient = dvec3(0.0);
  sum.value = std::isfinite(sum.value) ? std::clamp(sum.value, 0.0, unoccluded.value) : 0.0;
  return sum;
}

}  // namespace radiosity
