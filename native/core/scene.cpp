#include "core/scene.h"

#include "core/contact.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

namespace radiosity {
namespace {

[[noreturn]] void fail(const std::string& message) { throw std::invalid_argument(message); }


dvec3 polygon_area_normal(std::span<const dvec3> polygon) {
  dvec3 sum(0.0);
  for (size_t i = 1; i + 1 < polygon.size(); ++i) {
    sum += glm::cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
  }
  return 0.5 * sum;
}

double polygon_diameter(std::span<const dvec3> polygon) {
  double d = 0.0;
  for (size_t i = 0; i < polygon.size(); ++i) {
    for (size_t j = i + 1; j < polygon.size(); ++j) d = std::max(d, glm::length(polygon[j] - polygon[i]));
  }
  return d;
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

// Ear clipping in the polygon's best-fit plane: Blender's n-gons may be concave.
std::vector<std::array<size_t, 3>> triangulate(std::span<const dvec3> polygon) {
  const dvec3 n = glm::normalize(polygon_area_normal(polygon));
  const dvec3 helper = std::abs(n.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t1 = glm::normalize(glm::cross(helper, n)), t2 = glm::cross(n, t1);
  std::vector<dvec2> p;
  for (const dvec3& v : polygon) p.push_back({glm::dot(v - polygon[0], t1), glm::dot(v - polygon[0], t2)});
  const auto cross2 = [](dvec2 a, dvec2 b, dvec2 c) {
    return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
  };
  std::vector<size_t> remaining(polygon.size());
  for (size_t i = 0; i < remaining.size(); ++i) remaining[i] = i;
  std::vector<std::array<size_t, 3>> triangles;
  while (remaining.size() > 3) {
    bool clipped = false;
    for (size_t k = 0; k < remaining.size() && !clipped; ++k) {
      const size_t a = remaining[(k + remaining.size() - 1) % remaining.size()];
      const size_t b = remaining[k];
      const size_t c = remaining[(k + 1) % remaining.size()];
      if (cross2(p[a], p[b], p[c]) <= 0) continue;  // reflex corner
      bool contains = false;
      for (size_t other : remaining) {
        if (other == a || other == b || other == c) continue;
        if (cross2(p[a], p[b], p[other]) >= 0 && cross2(p[b], p[c], p[other]) >= 0 &&
            cross2(p[c], p[a], p[other]) >= 0) {
          contains = true;
          break;
        }
      }
      if (contains) continue;
      triangles.push_back({a, b, c});
      remaining.erase(remaining.begin() + static_cast<std::ptrdiff_t>(k));
      clipped = true;
    }
    if (!clipped) {  // self-intersecting or degenerate outline: fall back to a fan
      for (size_t k = 1; k + 1 < remaining.size(); ++k) {
        triangles.push_back({remaining[0], remaining[k], remaining[k + 1]});
      }
      return triangles;
    }
  }
  triangles.push_back({remaining[0], remaining[1], remaining[2]});
  return triangles;
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
      fail("face_sizes[" + std::to_string(f) + "] = " + std::to_string(size) + ": a face needs at least 3 vertices");
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
      m << "vertex " << i / 3 << " lies " << std::abs(a.positions[i]) << " from the origin; coordinates beyond "
        << kMaxCoordinate << " cannot be solved (scale the scene down)";
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
    if (a.occludes[f] == 0 && (a.reflectance[3 * f] > 0.0 || a.reflectance[3 * f + 1] > 0.0 || a.reflectance[3 * f + 2] > 0.0)) {
      fail("face " + std::to_string(f) + " casts no shadow (occludes is False) but reflects: such a face stands for a "
           "light and must have reflectance 0");
    }
  }
  for (size_t i = 0; i < a.emission.size(); ++i) {
    const double e = a.emission[i];
    if (!std::isfinite(e) || e < 0.0 || e > kMaxInputRadiance) {
      std::ostringstream m;
      m << "emission of face " << i / 3 << " is " << e << "; it must lie in [0, " << kMaxInputRadiance << "]";
      fail(m.str());
    }
  }
}

}  // namespace

Scene make_scene(const SceneArrays& a) {
  check_sizes(a);
  check_values(a);
  Scene scene;
  scene.face_count = a.face_sizes.size();
  scene.vertex_count = a.positions.size() / 3;
  const auto vertex = [&](std::int64_t i) {
    const size_t k = static_cast<size_t>(i) * 3;
    return dvec3(a.positions[k], a.positions[k + 1], a.positions[k + 2]);
  };
  dvec3 lo(1e300), hi(-1e300);
  for (size_t v = 0; v < scene.vertex_count; ++v) {
    lo = glm::min(lo, vertex(static_cast<std::int64_t>(v)));
    hi = glm::max(hi, vertex(static_cast<std::int64_t>(v)));
  }
  scene.diameter = glm::length(hi - lo);
  if (!(scene.diameter >= kMinSceneSize)) {
    std::ostringstream m;
    m << "the scene is " << scene.diameter << " across; scenes smaller than " << kMinSceneSize
      << " cannot be solved (scale the scene up)";
    fail(m.str());
  }
  const double reach = std::max(glm::length(lo), glm::length(hi));
  if (!(scene.diameter >= kMinRelativeSize * reach)) {
    std::ostringstream m;
    m << "the scene is " << scene.diameter << " across but " << reach
      << " from the origin: too far for its size to be solved precisely (move it to the origin)";
    fail(m.str());
  }

  size_t offset = 0;
  std::vector<dvec3> polygon;
  for (size_t f = 0; f < scene.face_count; ++f) {
    const size_t size = static_cast<size_t>(a.face_sizes[f]);
    polygon.clear();
    for (size_t k = 0; k < size; ++k) polygon.push_back(vertex(a.face_vertices[offset + k]));
    offset += size;
    PatchBuilder builder{scene,
                         Rgb(a.reflectance[3 * f], a.reflectance[3 * f + 1], a.reflectance[3 * f + 2]),
                         Rgb(a.emission[3 * f], a.emission[3 * f + 1], a.emission[3 * f + 2]),
                         a.two_sided.empty() || a.two_sided[f] != 0, a.occludes.empty() || a.occludes[f] != 0,
                         static_cast<std::uint32_t>(f)};
    const double diameter = polygon_diameter(polygon);
    if (!(glm::length(polygon_area_normal(polygon)) > kDegenerate * diameter * diameter)) {
      scene.skipped.push_back({static_cast<std::uint32_t>(f),
                               diameter > 0.0 ? "zero area (collinear vertices)"
                                              : "zero area (coincident vertices)"});
      continue;
    }
    if (size == 3 || (size == 4 && is_convex_planar_quad(polygon))) {
      builder.add(polygon);
    } else {
      for (const auto& t : triangulate(polygon)) {
        const dvec3 tri[3] = {polygon[t[0]], polygon[t[1]], polygon[t[2]]};
        builder.add(tri);
      }
    }
    if (builder.made == 0) {
      scene.skipped.push_back({static_cast<std::uint32_t>(f), "degenerate after triangulation"});
    }
  }
  if (scene.patches.empty()) {
    fail("every face is degenerate (zero area); nothing to solve");
  }
  mesh_contacts(scene);
  for (const Patch& p : scene.patches) {
    if (!p.sides[0].present && !p.sides[1].present) continue;
    scene.total_area += p.area;
    for (const PatchSide& side : p.sides)
      if (side.present) scene.emitted_power += luminance(side.emission) * p.area;
  }
  for (size_t i = 0; i < a.lights.size(); ++i) check_light(a.lights[i], i);
  for (const Light& light : a.lights)
    if (luminance(light.colour) > 0.0) scene.lights.push_back(light);
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
  if (!(scene.emitted_power > 0.0) && scene.lights.empty()) {
    fail("the scene has no emitter: no face emits, and there is no light and no world colour");
  }
  return scene;
}

}  // namespace radiosity
