#include "radiosity/scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/geometry/polygon.h"
#include "core/scene/contact.h"

namespace radiosity {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }

dvec3 polygon_area_normal(std::span<const dvec3> polygon) {
  return 0.5 * twice_area_normal(polygon);
}

// Relative size below which a face counts as degenerate.
constexpr double kDegenerate = 1e-10;
// Relative distance from the plane under which a quad counts as planar.
constexpr double kPlanar = 1e-6;

struct PatchBuilder {
  Scene& scene;
  const Rgb reflectance, emission;
  const bool two_sided;
  const bool occludes;
  const std::uint32_t face;
  int made = 0;

  // Adds a triangle or convex planar quad; false if degenerate.
  bool add(std::span<const dvec3> corners) {
    const dvec3 area_normal = polygon_area_normal(corners);
    const double area = glm::length(area_normal);
    const double diameter = polygon_diameter(corners);
    if (!(area > kDegenerate * diameter * diameter)) return false;
    Patch p;
    p.corner_count = static_cast<std::uint8_t>(corners.size());
    std::copy(corners.begin(), corners.end(), p.corners.begin());
    p.surface = face;
    p.occludes = occludes;
    p.normal = area_normal / area;
    p.area = area;
    for (std::uint8_t side = 0; side < 2; ++side) {
      PatchSide& s = p.sides[side];
      s.present = side == 0 || two_sided;
      s.face = face;
      s.face_side = side;
      s.reflectance = reflectance;
      s.emission = emission;
    }
    scene.patches.push_back(p);
    ++made;
    return true;
  }
};

bool is_convex_planar_quad(std::span<const dvec3> q) {
  const dvec3 normal = polygon_area_normal(q);
  const double length = glm::length(normal);
  const double diameter = polygon_diameter(q);
  if (!(length > 0.0)) return false;
  const dvec3 n = normal / length;
  for (const dvec3& v : q) {
    if (std::abs(glm::dot(n, v - q[0])) > kPlanar * diameter) return false;
  }
  for (int i = 0; i < 4; ++i) {
    const dvec3 turn = glm::cross(q[(i + 1) % 4] - q[i], q[(i + 2) % 4] - q[(i + 1) % 4]);
    if (glm::dot(turn, n) <= kDegenerate * diameter * diameter) return false;
  }
  return true;
}

// How far the polygon bends out of its best-fit plane (through the centroid,
// normal to its area vector), over its diameter.
double bend(std::span<const dvec3> polygon, const dvec3& normal, double diameter) {
  dvec3 centroid(0.0);
  for (const dvec3& v : polygon) centroid += v;
  centroid /= static_cast<double>(polygon.size());
  double most = 0.0;
  for (const dvec3& v : polygon) most = std::max(most, std::abs(glm::dot(normal, v - centroid)));
  return most / diameter;
}

// Whether the outline turns somewhere: not all its corners on one line.
bool turns(std::span<const dvec3> polygon, double diameter) {
  const size_t n = polygon.size();
  for (size_t i = 0; i < n; ++i) {
    const dvec3 turn =
        glm::cross(polygon[(i + 1) % n] - polygon[i], polygon[(i + 2) % n] - polygon[(i + 1) % n]);
    if (glm::length(turn) > kDegenerate * diameter * diameter) return true;
  }
  return false;
}

// Which way a -> b -> c turns (positive: left).
double turn(dvec2 a, dvec2 b, dvec2 c) { return cross2(b - a, c - a); }

// Whether two edges that share no corner cross or touch, in the plane.
bool edges_meet(dvec2 a, dvec2 b, dvec2 c, dvec2 d) {
  const double d1 = turn(a, b, c), d2 = turn(a, b, d), d3 = turn(c, d, a), d4 = turn(c, d, b);
  const bool straddle_ab = (d1 > 0) != (d2 > 0) || d1 == 0 || d2 == 0;
  const bool straddle_cd = (d3 > 0) != (d4 > 0) || d3 == 0 || d4 == 0;
  return straddle_ab && straddle_cd && std::min(a.x, b.x) <= std::max(c.x, d.x) &&
         std::min(c.x, d.x) <= std::max(a.x, b.x) && std::min(a.y, b.y) <= std::max(c.y, d.y) &&
         std::min(c.y, d.y) <= std::max(a.y, b.y);
}

// Whether the outline crosses or touches itself. Polygons with more corners
// than this are not checked (the check is quadratic; ear clipping still
// notices an outline it cannot cut).
constexpr size_t kMaxCheckedCorners = 256;
bool self_intersecting(const std::vector<dvec2>& p) {
  const size_t n = p.size();
  if (n < 4 || n > kMaxCheckedCorners) return false;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // neighbours through the last corner
      if (edges_meet(p[i], p[(i + 1) % n], p[j], p[(j + 1) % n])) return true;
    }
  }
  return false;
}

// The polygon in coordinates of the plane with unit normal n.
std::vector<dvec2> project(std::span<const dvec3> polygon, const dvec3& n) {
  const dvec3 helper = std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t1 = glm::normalize(glm::cross(helper, n)), t2 = glm::cross(n, t1);
  std::vector<dvec2> p;
  for (const dvec3& v : polygon)
    p.push_back({glm::dot(v - polygon[0], t1), glm::dot(v - polygon[0], t2)});
  return p;
}

// Ear clipping in the polygon's best-fit plane: Blender's n-gons may be
// concave. The first ear tried is at corner 1, so a quad splits along its
// 0-2 diagonal unless that lies outside it: the triangles Blender draws and
// Cycles renders for a non-planar quad. Returns false when no ear can be cut:
// the outline crosses itself.
bool triangulate(const std::vector<dvec2>& p, std::vector<std::array<size_t, 3>>& triangles) {
  triangles.clear();
  std::vector<size_t> remaining(p.size());
  for (size_t i = 0; i < remaining.size(); ++i) remaining[i] = i;
  size_t start = 1;
  while (remaining.size() > 3) {
    bool clipped = false;
    for (size_t step = 0; step < remaining.size() && !clipped; ++step) {
      const size_t k = (start + step) % remaining.size();
      const size_t a = remaining[(k + remaining.size() - 1) % remaining.size()];
      const size_t b = remaining[k];
      const size_t c = remaining[(k + 1) % remaining.size()];
      if (turn(p[a], p[b], p[c]) <= 0) continue;  // reflex corner
      bool contains = false;
      for (size_t other : remaining) {
        if (other == a || other == b || other == c) continue;
        if (turn(p[a], p[b], p[other]) >= 0 && turn(p[b], p[c], p[other]) >= 0 &&
            turn(p[c], p[a], p[other]) >= 0) {
          contains = true;
          break;
        }
      }
      if (contains) continue;
      triangles.push_back({a, b, c});
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(k));
      start = k % remaining.size();
      clipped = true;
    }
    if (!clipped) return false;
  }
  triangles.push_back({remaining[0], remaining[1], remaining[2]});
  return true;
}

void check_sizes(const SceneArrays& a) {
  if (a.positions.size() % 3 != 0) fail("positions must have shape (n, 3)");
  const size_t faces = a.face_sizes.size();
  if (faces == 0) fail("the scene has no faces (face_sizes is empty)");
  if (a.positions.empty()) fail("the scene has no vertices (positions is empty)");
  if (a.reflectance.size() != 3 * faces) {
    fail("reflectance must have shape (" + std::to_string(faces) + ", 3), one RGB per face");
  }
  if (a.emission.size() != 3 * faces) {
    fail("emission must have shape (" + std::to_string(faces) + ", 3), one RGB per face");
  }
  if (!a.two_sided.empty() && a.two_sided.size() != faces) {
    fail("two_sided must have one entry per face (" + std::to_string(faces) + ")");
  }
  if (!a.occludes.empty() && a.occludes.size() != faces) {
    fail("occludes must have one entry per face (" + std::to_string(faces) + ")");
  }
  // Summed in size_t with each term bounded, so sizes cannot wrap around.
  size_t total = 0;
  for (size_t f = 0; f < faces; ++f) {
    const std::int64_t size = a.face_sizes[f];
    if (size < 3) {
      fail("face_sizes[" + std::to_string(f) + "] = " + std::to_string(size) +
           ": a face needs at least 3 vertices");
    }
    if (static_cast<std::uint64_t>(size) > a.face_vertices.size() - total) {
      fail("face_sizes adds up to more than the " + std::to_string(a.face_vertices.size()) +
           " entries of face_vertices (at face " + std::to_string(f) + ")");
    }
    total += static_cast<size_t>(size);
  }
  if (total != a.face_vertices.size()) {
    fail("face_vertices has " + std::to_string(a.face_vertices.size()) +
         " entries but face_sizes adds up to " + std::to_string(total));
  }
}

void check_values(const SceneArrays& a) {
  const size_t vertices = a.positions.size() / 3;
  for (size_t i = 0; i < a.positions.size(); ++i) {
    if (!std::isfinite(a.positions[i])) {
      fail("positions contains a non-finite value at vertex " + std::to_string(i / 3));
    }
    if (std::abs(a.positions[i]) > kMaxCoordinate) {
      std::ostringstream m;
      m << "vertex " << i / 3 << " lies " << std::abs(a.positions[i])
        << " from the origin; coordinates beyond " << kMaxCoordinate
        << " cannot be solved (scale the scene down)";
      fail(m.str());
    }
  }
  for (size_t i = 0; i < a.face_vertices.size(); ++i) {
    const std::int64_t v = a.face_vertices[i];
    if (v < 0 || static_cast<size_t>(v) >= vertices) {
      fail("face_vertices[" + std::to_string(i) + "] = " + std::to_string(v) +
           " is out of range for " + std::to_string(vertices) + " vertices");
    }
  }
  for (size_t i = 0; i < a.reflectance.size(); ++i) {
    const double r = a.reflectance[i];
    if (!std::isfinite(r) || r < 0.0 || r > 1.0) {
      std::ostringstream m;
      m << "reflectance of face " << i / 3 << " is " << r << "; it must lie in [0, 1]";
      fail(m.str());
    }
  }
  // A face that casts no shadow stands for a light (Blender's light objects):
  // it would receive light through surfaces it lies on, so it must not reflect.
  for (size_t f = 0; f < a.occludes.size(); ++f) {
    if (a.occludes[f] == 0 && (a.reflectance[3 * f] > 0.0 || a.reflectance[3 * f + 1] > 0.0 ||
                               a.reflectance[3 * f + 2] > 0.0)) {
      fail("face " + std::to_string(f) +
           " casts no shadow (occludes is False) but reflects: such a face stands for a "
           "light and must have reflectance 0");
    }
  }
  for (size_t i = 0; i < a.emission.size(); ++i) {
    const double e = a.emission[i];
    if (!std::isfinite(e) || e < 0.0 || e > kMaxInputRadiance) {
      std::ostringstream m;
      m << "emission of face " << i / 3 << " is " << e << "; it must lie in [0, "
        << kMaxInputRadiance << "]";
      fail(m.str());
    }
  }
}

// A light in the solver's frame: H = I cos / d^2 keeps its value as d scales
// when I scales with d^2; a sun's or the sky's H has no length in it.
Light in_frame(Light light, const SolverFrame& frame) {
  if (light.kind == LightKind::Point || light.kind == LightKind::Spot) {
    light.position = frame.to_solver(light.position);
    light.radius *= frame.scale;
    light.colour *= frame.scale * frame.scale;
  }
  return light;
}

// The frame the solver works in (scene.h: centred, one unit across), from
// the input's extent, after checking the scene is large enough and near
// enough the origin to be solved precisely.
struct Extent {
  SolverFrame frame;
  double diameter = 0.0;  // in the input's units
  double reach = 0.0;     // the farthest corner of its bounds from the origin
};

Extent measure_extent(const SceneArrays& a, size_t vertex_count) {
  dvec3 lo(1e300), hi(-1e300);
  for (size_t v = 0; v < vertex_count; ++v) {
    const dvec3 p(a.positions[3 * v], a.positions[3 * v + 1], a.positions[3 * v + 2]);
    lo = glm::min(lo, p);
    hi = glm::max(hi, p);
  }
  Extent e;
  e.diameter = glm::length(hi - lo);
  if (!(e.diameter >= kMinSceneSize)) {
    std::ostringstream m;
    m << "the scene is " << e.diameter << " across; scenes smaller than " << kMinSceneSize
      << " cannot be solved (scale the scene up)";
    fail(m.str());
  }
  e.reach = std::max(glm::length(lo), glm::length(hi));
  if (!(e.diameter >= kMinRelativeSize * e.reach)) {
    std::ostringstream m;
    m << "the scene is " << e.diameter << " across but " << e.reach
      << " from the origin: too far for its size to be solved precisely (move it to the origin)";
    fail(m.str());
  }
  e.frame.origin = 0.5 * (lo + hi);
  e.frame.scale = 1.0 / e.diameter;
  return e;
}

// Input face f as patches of `scene` (scene.patches), or a note in
// scene.skipped of why it was left out; its repairs go to scene.repaired.
// `polygon` holds its corners in the solver's frame, repeated ones removed.
void add_face(Scene& scene, const SceneArrays& a, size_t f, std::vector<dvec3>& polygon,
              size_t repeated, double unrounded_diameter, const Extent& extent,
              double smallest_face, std::vector<std::array<size_t, 3>>& triangles) {
  const auto face = static_cast<std::uint32_t>(f);
  PatchBuilder builder{
      scene,
      Rgb(a.reflectance[3 * f], a.reflectance[3 * f + 1], a.reflectance[3 * f + 2]),
      Rgb(a.emission[3 * f], a.emission[3 * f + 1], a.emission[3 * f + 2]),
      a.two_sided.empty() || a.two_sided[f] != 0,
      a.occludes.empty() || a.occludes[f] != 0,
      face};
  const double diameter = polygon_diameter(polygon);
  const dvec3 area_normal = polygon_area_normal(polygon);
  // Under the smallest face before the grid rounded it (it may have rounded
  // it to a point).
  if (unrounded_diameter > 0.0 && unrounded_diameter < smallest_face) {
    scene.skipped.push_back({.face = face,
                             .issue = FaceIssue::TooSmall,
                             .size = unrounded_diameter / extent.frame.scale,
                             .scene_size = extent.diameter});
    return;
  }
  if (polygon.size() < 3 || !(glm::length(area_normal) > kDegenerate * diameter * diameter)) {
    const FaceIssue why = !(diameter > 0.0) ? FaceIssue::CoincidentCorners
                          : turns(polygon, diameter)
                              ? FaceIssue::CrossesItself  // lobes that cancel
                              : FaceIssue::CollinearCorners;
    scene.skipped.push_back({.face = face, .issue = why});
    return;
  }
  std::vector<FaceNote> repairs;
  if (repeated) {
    repairs.push_back({.face = face,
                       .issue = FaceIssue::RepeatedCorners,
                       .count = static_cast<std::uint32_t>(repeated)});
  }
  if (polygon.size() == 3 || (polygon.size() == 4 && is_convex_planar_quad(polygon))) {
    builder.add(polygon);
  } else {
    const dvec3 normal = glm::normalize(area_normal);
    const std::vector<dvec2> flat = project(polygon, normal);
    if (self_intersecting(flat) || !triangulate(flat, triangles)) {
      // A bow-tie has no inside: Blender draws it as triangles that overlap,
      // facing opposite ways, and each would send its light twice.
      scene.skipped.push_back({.face = face, .issue = FaceIssue::CrossesItself});
      return;
    }
    for (const auto& t : triangles) {
      const dvec3 tri[3] = {polygon[t[0]], polygon[t[1]], polygon[t[2]]};
      builder.add(tri);
    }
    const double bent = bend(polygon, normal, diameter);
    if (bent > kPlanar) {
      repairs.push_back({.face = face,
                         .issue = FaceIssue::NotPlanar,
                         .count = static_cast<std::uint32_t>(builder.made),
                         .bend = bent});
    }
  }
  if (builder.made == 0) {
    scene.skipped.push_back({.face = face, .issue = FaceIssue::NoTriangles});
    return;
  }
  scene.repaired.insert(scene.repaired.end(), repairs.begin(), repairs.end());
}

// Every input face as patches (add_face), in the solver's frame.
void add_faces(Scene& scene, const SceneArrays& a, const Extent& extent) {
  const auto world = [&](std::int64_t i) {
    const size_t k = static_cast<size_t>(i) * 3;
    return dvec3(a.positions[k], a.positions[k + 1], a.positions[k + 2]);
  };
  // Faces too small to solve in floating point (scene.h): the input's
  // coordinates carry their rounding at `reach` from the origin.
  const double smallest_face = std::max(kMinRelativeFaceSize * scene.diameter,
                                        kMinFaceSizeOfReach * extent.reach * extent.frame.scale);
  size_t offset = 0;
  std::vector<dvec3> polygon, unrounded;
  std::vector<std::array<size_t, 3>> triangles;
  for (size_t f = 0; f < scene.face_count; ++f) {
    const size_t size = static_cast<size_t>(a.face_sizes[f]);
    polygon.clear();
    unrounded.clear();
    for (size_t k = 0; k < size; ++k) {
      const dvec3 p = world(a.face_vertices[offset + k]);
      unrounded.push_back(extent.frame.scaled(p));
      const dvec3 v = extent.frame.to_solver(p);
      if (polygon.empty() || v != polygon.back()) polygon.push_back(v);
    }
    offset += size;
    while (polygon.size() > 1 && polygon.front() == polygon.back()) polygon.pop_back();
    add_face(scene, a, f, polygon, size - polygon.size(), polygon_diameter(unrounded), extent,
             smallest_face, triangles);
  }
}

// The area of the patches' sides and the power they emit (scene.h's totals).
void sum_area_and_power(Scene& scene) {
  for (const Patch& p : scene.patches) {
    if (!p.sides[0].present && !p.sides[1].present) continue;
    scene.total_area += p.area;
    for (const PatchSide& side : p.sides)
      if (side.present) scene.emitted_power += luminance(side.emission) * p.area;
  }
}

// The lights that shine, in the solver's frame, and the world's light as a sky.
void add_lights(Scene& scene, const SceneArrays& a) {
  for (size_t i = 0; i < a.lights.size(); ++i) check_light(a.lights[i], i);
  for (const Light& light : a.lights)
    if (luminance(light.colour) > 0.0) scene.lights.push_back(in_frame(light, scene.frame));
  for (int c = 0; c < 3; ++c) {
    if (!(a.world[c] >= 0.0 && a.world[c] <= kMaxInputRadiance)) {
      std::ostringstream m;
      m << "the world's radiance must lie in [0, " << kMaxInputRadiance << "]";
      fail(m.str());
    }
  }
  if (luminance(a.world) > 0.0) {
    Light sky;
    sky.kind = LightKind::Sky;
    sky.colour = a.world;
    scene.lights.push_back(sky);
  }
}

}  // namespace

std::string_view face_issue_name(FaceIssue issue) {
  switch (issue) {
    case FaceIssue::CoincidentCorners:
      return "coincident_corners";
    case FaceIssue::CollinearCorners:
      return "collinear_corners";
    case FaceIssue::CrossesItself:
      return "crosses_itself";
    case FaceIssue::TooSmall:
      return "too_small";
    case FaceIssue::NoTriangles:
      return "no_triangles";
    case FaceIssue::RepeatedCorners:
      return "repeated_corners";
    case FaceIssue::NotPlanar:
      return "not_planar";
  }
  return "unknown";
}

std::size_t noted_faces(std::span<const FaceNote> notes) {
  std::size_t faces = 0;
  for (size_t i = 0; i < notes.size(); ++i)
    if (i == 0 || notes[i].face != notes[i - 1].face) ++faces;
  return faces;
}

Scene make_scene(const SceneArrays& a) {
  check_sizes(a);
  check_values(a);
  Scene scene;
  scene.face_count = a.face_sizes.size();
  scene.vertex_count = a.positions.size() / 3;
  const Extent extent = measure_extent(a, scene.vertex_count);
  scene.frame = extent.frame;
  scene.diameter = extent.diameter * scene.frame.scale;
  add_faces(scene, a, extent);
  if (scene.patches.empty()) {
    fail("every face is degenerate or broken and was skipped (face " +
         std::to_string(scene.skipped.front().face) + ": " +
         std::string(face_issue_name(scene.skipped.front().issue)) + "); nothing to solve");
  }
  mesh_contacts(scene);
  sum_area_and_power(scene);
  add_lights(scene, a);
  if (!(scene.emitted_power > 0.0) && scene.lights.empty()) {
    fail("the scene has no emitter: no face emits, and there is no light and no world colour");
  }
  return scene;
}

}  // namespace radiosity
