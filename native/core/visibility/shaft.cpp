// Shaft culling between two elements (see shaft.h).
#include "core/visibility/shaft.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "core/geometry/polygon.h"

namespace radiosity {
namespace {

using Polygon2 = std::vector<dvec2>;

// Convex hull of 2D points, counter-clockwise (Andrew's monotone chain).
Polygon2 convex_hull(Polygon2 p) {
  if (p.size() < 3) return {};
  std::sort(p.begin(), p.end(),
            [](const dvec2& a, const dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  Polygon2 hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  hull.resize(k - 1);  // the last point repeats the first
  return hull;
}

// Part of convex `in` where w . q + c has sign `side` (Sutherland-Hodgman).
Polygon2 clip_half_plane(const Polygon2& in, const dvec2& w, double c, double side) {
  Polygon2 out;
  for (std::size_t i = 0; i < in.size(); ++i) {
    const dvec2& a = in[i];
    const dvec2& b = in[(i + 1) % in.size()];
    const double da = side * (glm::dot(w, a) + c), db = side * (glm::dot(w, b) + c);
    if (da >= 0.0) out.push_back(a);
    if ((da >= 0.0) != (db >= 0.0)) out.push_back(a + (da / (da - db)) * (b - a));
  }
  return out;
}

// Is convex `region` covered by the union of `triangles` (counter-clockwise)?
// Subtracts them one by one by successive half-planes; leftovers smaller than
// `tiny` (slivers along shared edges) count as covered.
bool covered(const Polygon2& region, const std::vector<Polygon2>& triangles, double tiny) {
  std::vector<Polygon2> pieces{region}, next;
  for (const Polygon2& t : triangles) {
    next.clear();
    for (const Polygon2& piece : pieces) {
      Polygon2 rest = piece;
      for (std::size_t i = 0; i < 3 && !rest.empty(); ++i) {
        const dvec2 d = t[(i + 1) % 3] - t[i];
        const dvec2 w(-d.y, d.x);
        const double c = -glm::dot(w, t[i]);
        Polygon2 outside = clip_half_plane(rest, w, c, -1.0);
        if (outside.size() >= 3 && signed_area(outside) > tiny) next.push_back(std::move(outside));
        rest = clip_half_plane(rest, w, c, +1.0);
        if (rest.size() < 3 || signed_area(rest) <= tiny) rest.clear();
      }
    }
    std::swap(pieces, next);
    if (pieces.empty()) return true;
  }
  return false;
}

// The plane n.x = offset has the receiver strictly on one side and the emitter
// strictly on the other.
bool plane_separates(const dvec3& normal, double offset, std::span<const dvec3> receiver,
                     std::span<const dvec3> emitter, double tol) {
  double rmin = 1e300, rmax = -1e300, emin = 1e300, emax = -1e300;
  for (const dvec3& p : receiver) {
    const double d = glm::dot(normal, p) - offset;
    rmin = std::min(rmin, d), rmax = std::max(rmax, d);
  }
  for (const dvec3& p : emitter) {
    const double d = glm::dot(normal, p) - offset;
    emin = std::min(emin, d), emax = std::max(emax, d);
  }
  return (rmax < -tol && emin > tol) || (rmin > tol && emax < -tol);
}

// Do the candidates lying in one plane block every segment between the two
// elements? They must separate the elements (all receiver corners strictly on
// one side of the plane, all emitter corners on the other), and cover the
// shaft's cross-section on the plane: the convex hull of the points where the
// corner-to-corner segments cross it (the hull of the corners meets the plane in
// exactly that hull).
bool plane_blocks_shaft(const OccluderScene& scene, const std::vector<std::uint32_t>& group,
                        const dvec3& normal, double offset, std::span<const dvec3> receiver,
                        std::span<const dvec3> emitter, double tol) {
  if (!plane_separates(normal, offset, receiver, emitter, tol)) return false;
  // A frame of the plane.
  const dvec3 helper = std::abs(normal.x) < 0.6 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 e1 = glm::normalize(glm::cross(normal, helper));
  const dvec3 e2 = glm::cross(normal, e1);
  const auto to_plane = [&](const dvec3& p) { return dvec2(glm::dot(p, e1), glm::dot(p, e2)); };
  Polygon2 crossings;
  for (const dvec3& a : receiver) {
    const double da = glm::dot(normal, a) - offset;
    for (const dvec3& b : emitter) {
      const double db = glm::dot(normal, b) - offset;
      crossings.push_back(to_plane(a + (da / (da - db)) * (b - a)));
    }
  }
  const Polygon2 region = convex_hull(crossings);
  const double area = signed_area(region);
  if (region.size() < 3 || !(area > 0.0)) return false;
  std::vector<Polygon2> triangles;
  for (std::uint32_t t : group) {
    Polygon2 tri{to_plane(scene.triangles[t].v[0]), to_plane(scene.triangles[t].v[1]),
                 to_plane(scene.triangles[t].v[2])};
    const double a = signed_area(tri);
    if (a == 0.0) continue;
    if (a < 0.0) std::swap(tri[1], tri[2]);
    triangles.push_back(tri);
  }
  return covered(region, triangles, 1e-12 * area);
}

// Clear, hidden or partial. "Hidden" is proved by one plane's candidates
// together (a wall made of several faces counts), never guessed; a missed proof
// only costs time (the link is then evaluated as partial).
ShaftVisibility classify(const OccluderScene& scene, const std::vector<std::uint32_t>& candidates,
                         std::span<const dvec3> receiver, std::span<const dvec3> emitter,
                         double tol) {
  if (candidates.empty()) return ShaftVisibility::clear;
  if (candidates.size() > 4096) return ShaftVisibility::partial;  // not worth the search
  // Candidates by plane: unit normal with a canonical sign, and offset. Sorting
  // puts coplanar triangles next to each other.
  struct PlaneOf {
    dvec3 normal;
    double offset;
    std::uint32_t triangle;
  };
  std::vector<PlaneOf> planes;
  planes.reserve(candidates.size());
  for (std::uint32_t t : candidates) {
    const Triangle& tri = scene.triangles[t];
    dvec3 normal = glm::cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]);
    const double len = glm::length(normal);
    if (!(len > 0.0)) continue;
    normal /= len;
    const double sign = normal.x != 0.0 ? normal.x : normal.y != 0.0 ? normal.y : normal.z;
    if (sign < 0.0) normal = -normal;
    planes.push_back({normal, glm::dot(normal, tri.v[0]), t});
  }
  std::sort(planes.begin(), planes.end(), [](const PlaneOf& a, const PlaneOf& b) {
    if (a.normal.x != b.normal.x) return a.normal.x < b.normal.x;
    if (a.normal.y != b.normal.y) return a.normal.y < b.normal.y;
    if (a.normal.z != b.normal.z) return a.normal.z < b.normal.z;
    return a.offset < b.offset;
  });
  std::vector<std::uint32_t> group;
  for (std::size_t i = 0; i < planes.size();) {
    const dvec3 normal = planes[i].normal;
    const double offset = planes[i].offset;
    // The plane must separate the two elements, else nothing in it blocks all.
    const bool separates = plane_separates(normal, offset, receiver, emitter, tol);
    group.clear();
    Aabb box;
    std::size_t j = i;
    for (; j < planes.size(); ++j) {
      const Triangle& u = scene.triangles[planes[j].triangle];
      const bool coplanar = std::abs(glm::dot(normal, u.v[0]) - offset) <= tol &&
                            std::abs(glm::dot(normal, u.v[1]) - offset) <= tol &&
                            std::abs(glm::dot(normal, u.v[2]) - offset) <= tol;
      if (!coplanar) break;
      group.push_back(planes[j].triangle);
      for (const dvec3& v : u.v) box.grow(v);
    }
    i = std::max(j, i + 1);
    if (!separates) continue;
    // Cheap necessary condition: the group's box holds every crossing point.
    bool inside_box = true;
    for (const dvec3& a : receiver) {
      const double da = glm::dot(normal, a) - offset;
      for (const dvec3& b : emitter) {
        const double db = glm::dot(normal, b) - offset;
        const dvec3 x = a + (da / (da - db)) * (b - a);
        inside_box = inside_box && glm::all(glm::greaterThanEqual(x, box.lo - tol)) &&
                     glm::all(glm::lessThanEqual(x, box.hi + tol));
      }
    }
    if (inside_box && plane_blocks_shaft(scene, group, normal, offset, receiver, emitter, tol))
      return ShaftVisibility::hidden;
  }
  return ShaftVisibility::partial;
}

bool box_outside(const Shaft& shaft, const Aabb& box) {
  if (box.lo.x > shaft.box.hi.x || box.hi.x < shaft.box.lo.x || box.lo.y > shaft.box.hi.y ||
      box.hi.y < shaft.box.lo.y || box.lo.z > shaft.box.hi.z || box.hi.z < shaft.box.lo.z)
    return true;
  for (const ShaftPlane& p : shaft.planes) {
    // The box corner deepest inside the plane.
    const dvec3 c(p.normal.x > 0.0 ? box.lo.x : box.hi.x, p.normal.y > 0.0 ? box.lo.y : box.hi.y,
                  p.normal.z > 0.0 ? box.lo.z : box.hi.z);
    if (p.distance(c) >= -shaft.tolerance) return true;
  }
  return false;
}

}  // namespace

OccluderScene make_occluder_scene(std::vector<Triangle> triangles,
                                  std::vector<std::uint32_t> face) {
  OccluderScene scene;
  scene.triangles = std::move(triangles);
  if (face.size() != scene.triangles.size()) {
    face.resize(scene.triangles.size());
    std::iota(face.begin(), face.end(), 0u);
  }
  scene.face = std::move(face);
  scene.bvh = build_scene_bvh(scene.triangles);
  return scene;
}

Shaft make_shaft(std::span<const dvec3> receiver, std::span<const dvec3> emitter) {
  Shaft shaft;
  std::vector<dvec3> points(receiver.begin(), receiver.end());
  points.insert(points.end(), emitter.begin(), emitter.end());
  for (const dvec3& p : points) shaft.box.grow(p);
  const double size = glm::length(shaft.box.hi - shaft.box.lo);
  shaft.tolerance = 1e-9 * size;
  const double tol = shaft.tolerance;
  bool any_volume = false;
  const std::size_t k = points.size();
  for (std::size_t i = 0; i < k; ++i)
    for (std::size_t j = i + 1; j < k; ++j)
      for (std::size_t l = j + 1; l < k; ++l) {
        dvec3 n = glm::cross(points[j] - points[i], points[l] - points[i]);
        const double len = glm::length(n);
        if (!(len > 1e-12 * size * size)) continue;
        n /= len;
        double dmin = 1e300, dmax = -1e300;
        for (const dvec3& p : points) {
          const double d = glm::dot(n, p - points[i]);
          dmin = std::min(dmin, d), dmax = std::max(dmax, d);
          if (dmax > tol && dmin < -tol) break;  // most triples: no need to see the rest
        }
        if (dmax > tol && dmin < -tol) continue;  // points on both sides: not a hull face
        if (dmax > tol || dmin < -tol) any_volume = true;
        ShaftPlane plane;
        if (dmax <= tol) {
          plane.normal = n;
          plane.offset = glm::dot(n, points[i]) + std::max(0.0, dmax);
        } else {
          plane.normal = -n;
          plane.offset = -(glm::dot(n, points[i]) + std::min(0.0, dmin));
        }
        const bool duplicate =
            std::any_of(shaft.planes.begin(), shaft.planes.end(), [&](const ShaftPlane& q) {
              return glm::dot(q.normal, plane.normal) > 1.0 - 1e-12 &&
                     std::abs(q.offset - plane.offset) <= tol;
            });
        if (!duplicate) shaft.planes.push_back(plane);
      }
  shaft.flat = !any_volume;
  return shaft;
}

bool shaft_overlaps(const Shaft& shaft, const Triangle& t) {
  if (shaft.flat) return false;
  Aabb box;
  for (const dvec3& v : t.v) box.grow(v);
  if (box.lo.x > shaft.box.hi.x || box.hi.x < shaft.box.lo.x || box.lo.y > shaft.box.hi.y ||
      box.hi.y < shaft.box.lo.y || box.lo.z > shaft.box.hi.z || box.hi.z < shaft.box.lo.z)
    return false;
  for (const ShaftPlane& p : shaft.planes) {
    // All three corners outside or on one face plane: no point in the interior.
    if (p.distance(t.v[0]) >= -shaft.tolerance && p.distance(t.v[1]) >= -shaft.tolerance &&
        p.distance(t.v[2]) >= -shaft.tolerance)
      return false;
  }
  return true;
}

ShaftCulling cull_shaft(const OccluderScene& scene, std::span<const dvec3> receiver,
                        std::uint32_t receiver_face, std::span<const dvec3> emitter,
                        std::uint32_t emitter_face, std::size_t limit) {
  ShaftCulling out;
  const Shaft shaft = make_shaft(receiver, emitter);
  if (shaft.flat) return out;  // coplanar elements exchange nothing
  traverse_scene_bvh(
      scene.bvh, [&](const Aabb& box) { return !out.truncated && !box_outside(shaft, box); },
      [&](std::uint32_t t) {
        const std::uint32_t f = scene.face[t];
        if (out.truncated || f == receiver_face || f == emitter_face) return;
        if (!shaft_overlaps(shaft, scene.triangles[t])) return;
        if (out.candidates.size() == limit) {
          out.truncated = true;
          return;
        }
        out.candidates.push_back(t);
      });
  std::sort(out.candidates.begin(), out.candidates.end());
  out.visibility = classify(scene, out.candidates, receiver, emitter, shaft.tolerance);
  return out;
}

ShaftCulling cull_shaft_brute_force(const OccluderScene& scene, std::span<const dvec3> receiver,
                                    std::uint32_t receiver_face, std::span<const dvec3> emitter,
                                    std::uint32_t emitter_face) {
  ShaftCulling out;
  const Shaft shaft = make_shaft(receiver, emitter);
  if (shaft.flat) return out;
  for (std::uint32_t t = 0; t < scene.triangles.size(); ++t) {
    const std::uint32_t f = scene.face[t];
    if (f == receiver_face || f == emitter_face) continue;
    if (shaft_overlaps(shaft, scene.triangles[t])) out.candidates.push_back(t);
  }
  out.visibility = classify(scene, out.candidates, receiver, emitter, shaft.tolerance);
  return out;
}

}  // namespace radiosity
