// Shaft culling between two elements (see shaft.h).
#include "core/shaft.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace radiosity {
namespace {

double cross2(const dvec2& a, const dvec2& b) { return a.x * b.y - a.y * b.x; }

// Area of the convex hull of 2D points (Andrew's monotone chain).
double convex_hull_area(std::vector<dvec2> p) {
  if (p.size() < 3) return 0.0;
  std::sort(p.begin(), p.end(), [](const dvec2& a, const dvec2& b) {
    return a.x < b.x || (a.x == b.x && a.y < b.y);
  });
  std::vector<dvec2> hull(2 * p.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  for (std::size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && cross2(hull[k - 1] - hull[k - 2], p[i] - hull[k - 2]) <= 0.0) --k;
    hull[k++] = p[i];
  }
  double area = 0.0;
  for (std::size_t i = 0; i + 1 < k; ++i) area += cross2(hull[i], hull[i + 1]);
  return 0.5 * area;
}

// A face can prove "hidden" on its own if its triangles are coplanar and their
// union is convex (its area equals that of the hull of its vertices).
bool is_planar_convex(const std::vector<Triangle>& triangles, const std::vector<std::uint32_t>& tris) {
  if (tris.empty()) return false;
  const Triangle& t0 = triangles[tris[0]];
  dvec3 normal = glm::cross(t0.v[1] - t0.v[0], t0.v[2] - t0.v[0]);
  const double len = glm::length(normal);
  if (!(len > 0.0)) return false;
  normal /= len;
  double size = 0.0, area = 0.0;
  for (std::uint32_t t : tris)
    for (const dvec3& v : triangles[t].v) size = std::max(size, glm::length(v - t0.v[0]));
  const dvec3 e1 = glm::normalize(t0.v[1] - t0.v[0]);
  const dvec3 e2 = glm::cross(normal, e1);
  std::vector<dvec2> points;
  for (std::uint32_t t : tris) {
    const Triangle& tri = triangles[t];
    for (const dvec3& v : tri.v) {
      if (std::abs(glm::dot(normal, v - t0.v[0])) > 1e-9 * size) return false;
      points.push_back({glm::dot(v - t0.v[0], e1), glm::dot(v - t0.v[0], e2)});
    }
    area += 0.5 * glm::length(glm::cross(tri.v[1] - tri.v[0], tri.v[2] - tri.v[0]));
  }
  const double hull = convex_hull_area(points);
  return area > 0.0 && std::abs(hull - area) <= 1e-9 * area;
}

// Point inside triangle (inclusive, relative tolerance), the point on its plane.
bool inside_triangle(const Triangle& t, const dvec3& p) {
  const dvec3 n = glm::cross(t.v[1] - t.v[0], t.v[2] - t.v[0]);
  const double nn = glm::dot(n, n);
  if (!(nn > 0.0)) return false;
  for (int i = 0; i < 3; ++i) {
    const dvec3& a = t.v[i];
    const dvec3& b = t.v[(i + 1) % 3];
    if (glm::dot(glm::cross(b - a, p - a), n) < -1e-12 * nn) return false;
  }
  return true;
}

// Every segment from a receiver corner to an emitter corner crosses the plane of
// `tris` (the two elements strictly on either side) inside one of `tris`. The
// crossings span the shaft's cross-section on that plane (the hull of the
// corners meets the plane in the hull of these points), so when the triangles'
// union is convex, every segment between the elements is blocked.
bool blocks_shaft(const std::vector<Triangle>& triangles, std::span<const std::uint32_t> tris,
                  std::span<const dvec3> receiver, std::span<const dvec3> emitter, double tol) {
  const Triangle& t0 = triangles[tris[0]];
  dvec3 normal = glm::cross(t0.v[1] - t0.v[0], t0.v[2] - t0.v[0]);
  const double len = glm::length(normal);
  if (!(len > 0.0)) return false;
  normal /= len;
  const double offset = glm::dot(normal, t0.v[0]);
  double rmin = 1e300, rmax = -1e300, emin = 1e300, emax = -1e300;
  for (const dvec3& p : receiver) {
    const double d = glm::dot(normal, p) - offset;
    rmin = std::min(rmin, d), rmax = std::max(rmax, d);
  }
  for (const dvec3& p : emitter) {
    const double d = glm::dot(normal, p) - offset;
    emin = std::min(emin, d), emax = std::max(emax, d);
  }
  const bool separates = (rmax < -tol && emin > tol) || (rmin > tol && emax < -tol);
  if (!separates) return false;
  for (const dvec3& a : receiver) {
    const double da = glm::dot(normal, a) - offset;
    for (const dvec3& b : emitter) {
      const double db = glm::dot(normal, b) - offset;
      const dvec3 p = a + (da / (da - db)) * (b - a);
      bool covered = false;
      for (std::uint32_t t : tris)
        if (inside_triangle(triangles[t], p)) {
          covered = true;
          break;
        }
      if (!covered) return false;
    }
  }
  return true;
}

ShaftVisibility classify(const OccluderScene& scene, const std::vector<std::uint32_t>& candidates,
                         std::span<const dvec3> receiver, std::span<const dvec3> emitter,
                         double tol) {
  if (candidates.empty()) return ShaftVisibility::clear;
  std::vector<std::uint32_t> tested_faces;
  for (std::uint32_t t : candidates) {
    const std::uint32_t f = scene.face[t];
    if (scene.face_planar_convex[f]) {
      if (std::find(tested_faces.begin(), tested_faces.end(), f) != tested_faces.end()) continue;
      tested_faces.push_back(f);
      if (blocks_shaft(scene.triangles, scene.face_triangles[f], receiver, emitter, tol))
        return ShaftVisibility::hidden;
    } else if (blocks_shaft(scene.triangles, std::span<const std::uint32_t>(&t, 1), receiver,
                            emitter, tol)) {
      return ShaftVisibility::hidden;
    }
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

OccluderScene make_occluder_scene(std::vector<Triangle> triangles, std::vector<std::uint32_t> face) {
  OccluderScene scene;
  scene.triangles = std::move(triangles);
  if (face.size() != scene.triangles.size()) {
    face.resize(scene.triangles.size());
    std::iota(face.begin(), face.end(), 0u);
  }
  scene.face = std::move(face);
  std::uint32_t faces = 0;
  for (std::uint32_t f : scene.face) faces = std::max(faces, f + 1);
  scene.face_triangles.resize(faces);
  for (std::uint32_t t = 0; t < scene.face.size(); ++t) scene.face_triangles[scene.face[t]].push_back(t);
  scene.face_planar_convex.resize(faces);
  for (std::uint32_t f = 0; f < faces; ++f)
    scene.face_planar_convex[f] = is_planar_convex(scene.triangles, scene.face_triangles[f]);
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
        const bool duplicate = std::any_of(shaft.planes.begin(), shaft.planes.end(), [&](const ShaftPlane& q) {
          return glm::dot(q.normal, plane.normal) > 1.0 - 1e-12 && std::abs(q.offset - plane.offset) <= tol;
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
                        std::uint32_t emitter_face) {
  ShaftCulling out;
  const Shaft shaft = make_shaft(receiver, emitter);
  if (shaft.flat) return out;  // coplanar elements exchange nothing
  traverse_scene_bvh(
      scene.bvh, [&](const Aabb& box) { return !box_outside(shaft, box); },
      [&](std::uint32_t t) {
        const std::uint32_t f = scene.face[t];
        if (f == receiver_face || f == emitter_face) return;
        if (shaft_overlaps(shaft, scene.triangles[t])) out.candidates.push_back(t);
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
