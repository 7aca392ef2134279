#include "core/solve/direct_light.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <string>

#include "core/geometry/form_factor.h"
#include "core/geometry/polygon.h"
#include "core/visibility/sampled_visibility.h"
#include "core/visibility/shaft.h"
#include "core/visibility/visible_polygon.h"
#include "radiosity/scene.h"

namespace radiosity {
namespace {

// A disk's polygon: 16 sides, its radius grown so that its area is the disk's.
constexpr int kDiskSides = 16;
using DiskPolygon = std::array<dvec3, kDiskSides>;

double disk_growth() {
  const double n = kDiskSides;
  return std::sqrt(std::numbers::pi / (0.5 * n * std::sin(2.0 * std::numbers::pi / n)));
}

// Counter-clockwise about `normal` (its front faces where normal points).
DiskPolygon disk_polygon(const dvec3& centre, const dvec3& normal, double radius) {
  const dvec3 helper = std::abs(normal.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t1 = glm::normalize(glm::cross(helper, normal));
  const dvec3 t2 = glm::cross(normal, t1);
  const double r = radius * disk_growth();
  DiskPolygon out;
  for (int k = 0; k < kDiskSides; ++k) {
    const double a = 2.0 * std::numbers::pi * k / kDiskSides;
    out[static_cast<size_t>(k)] = centre + r * (std::cos(a) * t1 + std::sin(a) * t2);
  }
  return out;
}

// A triangle around `centre` facing along `normal`, holding the disk of
// `radius` about it: the far end of a shaft towards a point or a direction.
std::array<dvec3, 3> triangle_around(const dvec3& centre, const dvec3& normal, double radius) {
  const dvec3 helper = std::abs(normal.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t1 = glm::normalize(glm::cross(helper, normal));
  const dvec3 t2 = glm::cross(normal, t1);
  std::array<dvec3, 3> out;
  for (int k = 0; k < 3; ++k) {
    const double a = 2.0 * std::numbers::pi * k / 3;
    out[static_cast<size_t>(k)] = centre + 2.0 * radius * (std::cos(a) * t1 + std::sin(a) * t2);
  }
  return out;
}

// Past this many candidate occluders, shadow rays go through Embree (as links).
constexpr std::size_t kRayCrossover = 32;

// Visible shares below this fraction of the unoccluded form factor are
// rounding: a sample a millionth from a face meeting its own (the inside of
// a box's edge) sees that face edge-on, where its projection is
// ill-conditioned. A millionth of a light is far below what anyone can see.
constexpr double kRounding = 1e-6;

// Suns narrower than this (radians) are a direction: hard shadows by one ray.
constexpr double kPointSun = 1e-4;

// Shadow rays from a receiver element's samples to points `target(x)` (a
// point light, or far along the sun's direction): the candidates of the shaft
// from the element to `end` (which holds every target) are tested in double
// precision, so a sample a millionth from a face that meets the receiver (the
// inside of a box's edge) is not let through as Embree's single-precision
// margins would; past the crossover, Embree traverses the scene.
template <typename Target>
void shadow_rays(const SceneOccluders& occluders, std::span<const dvec3> receiver,
                 std::uint32_t face, std::span<const dvec3> x, std::span<const dvec3> end,
                 bool sampled, const Target& target, bool* blocked) {
  const ShaftCulling culling =
      cull_shaft(occluders.shafts, receiver, face, end, kNoFace,
                 sampled ? kRayCrossover : std::numeric_limits<std::size_t>::max());
  for (size_t s = 0; s < x.size(); ++s) {
    const dvec3 to = target(x[s]);
    if (culling.visibility == ShaftVisibility::hidden) {
      blocked[s] = true;
    } else if (culling.visibility == ShaftVisibility::clear) {
      blocked[s] = false;
    } else if (culling.truncated) {
      blocked[s] = occluders.rays->occluded(x[s], to, face);
    } else {
      blocked[s] = false;
      for (std::uint32_t t : culling.candidates) {
        if (segment_hits_triangle(x[s], to, occluders.shafts.triangles[t])) {
          blocked[s] = true;
          break;
        }
      }
    }
  }
}

}  // namespace

std::optional<LightKind> parse_light_kind(std::string_view name) {
  if (name == "point") return LightKind::Point;
  if (name == "spot") return LightKind::Spot;
  if (name == "sun") return LightKind::Sun;
  return std::nullopt;
}

namespace {
std::string to_text(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

void check_light(const Light& light, std::size_t index) {
  const std::string which = "light " + std::to_string(index) + ": ";
  const auto finite = [](const dvec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
  };
  for (int c = 0; c < 3; ++c)
    if (!(light.colour[c] >= 0.0 && light.colour[c] <= kMaxInputRadiance))
      throw std::invalid_argument(which + "its colour (intensity) must lie in [0, " +
                                  to_text(kMaxInputRadiance) + "]");
  if (!(finite(light.position) && glm::length(light.position) <= kMaxCoordinate))
    throw std::invalid_argument(which + "its position must be finite and within " +
                                to_text(kMaxCoordinate) + " of the origin");
  if (!finite(light.direction) || !(glm::length(light.direction) > 0.0))
    throw std::invalid_argument(which + "its direction must be finite and not zero");
  if (!(std::isfinite(light.radius) && light.radius >= 0.0))
    throw std::invalid_argument(which + "its radius must be finite and >= 0");
  if (!(std::isfinite(light.angle) && light.angle >= 0.0 && light.angle < std::numbers::pi))
    throw std::invalid_argument(which + "a sun's angle must lie in [0, pi)");
  if (!(light.cos_half_angle >= -1.0 && light.cos_half_angle <= 1.0))
    throw std::invalid_argument(which + "a spot's cos_half_angle must lie in [-1, 1]");
  if (!(std::isfinite(light.blend_width) && light.blend_width >= 0.0))
    throw std::invalid_argument(which + "a spot's blend_width must be finite and >= 0");
  if (light.kind == LightKind::Sky)
    throw std::invalid_argument(which + "the sky is the world colour, not a light");
}

SpotFactor spot_factor(const Light& light, double c) {
  if (light.kind != LightKind::Spot) return {1.0, 0.0};
  double s = 0.0, ds = 0.0;
  if (light.blend_width > 0.0) {
    const double t = (c - light.cos_half_angle) / light.blend_width;
    if (t >= 1.0) {
      s = 1.0;
    } else if (t > 0.0) {
      s = t * t * (3.0 - 2.0 * t);
      ds = 6.0 * t * (1.0 - t) / light.blend_width;
    }
  } else {
    s = c > light.cos_half_angle ? 1.0 : 0.0;
  }
  if (light.cosine_falloff) return {std::max(c, 0.0) * s, c > 0.0 ? s + c * ds : 0.0};
  return {s, ds};
}

DirectLight::DirectLight(const Hierarchy& hierarchy, const SceneOccluders& occluders,
                         VisibilityMode visibility, int rays, Oracle oracle, double geometric_scale)
    : hierarchy_(hierarchy),
      occluders_(occluders),
      visibility_(visibility),
      rays_(rays),
      oracle_(oracle),
      geometric_scale_(geometric_scale) {
  dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const Patch& p : hierarchy.scene().patches) {
    for (int k = 0; k < p.corner_count; ++k) {
      lo = glm::min(lo, p.corners[static_cast<size_t>(k)]);
      hi = glm::max(hi, p.corners[static_cast<size_t>(k)]);
    }
  }
  const double diameter = glm::length(hi - lo);
  far_ = 4.0 * diameter + 1e-9;
  // The sky box: a hundredth of the scene's size clear of it, so no face lies on it.
  const dvec3 margin(0.01 * diameter + 1e-9);
  lo -= margin;
  hi += margin;
  for (int axis = 0; axis < 3; ++axis) {
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      dvec3 normal(0.0);
      normal[axis] = side == 0 ? 1.0 : -1.0;  // looking in
      std::array<dvec3, 4> face;
      const double at = side == 0 ? lo[axis] : hi[axis];
      const double us[4] = {lo[u], hi[u], hi[u], lo[u]}, vs[4] = {lo[v], lo[v], hi[v], hi[v]};
      for (int k = 0; k < 4; ++k) {
        dvec3 c(0.0);
        c[axis] = at;
        c[u] = us[k];
        c[v] = vs[k];
        face[static_cast<size_t>(k)] = c;
      }
      if (glm::dot(glm::cross(face[1] - face[0], face[2] - face[0]), normal) < 0.0)
        std::swap(face[1], face[3]);
      sky_[static_cast<size_t>(2 * axis + side)] = face;
    }
  }
}

std::vector<LightLink> DirectLight::initial_links() const {
  std::vector<LightLink> out;
  const std::size_t lights = hierarchy_.scene().lights.size();
  for (std::size_t r = 0; r < hierarchy_.root_count(); ++r) {
    const std::int32_t root =
        hierarchy_.root(static_cast<std::uint32_t>(r / 2), static_cast<int>(r % 2));
    if (root == kNone || !(luminance(hierarchy_.reflectance(hierarchy_.element(root))) > 0.0))
      continue;
    for (std::size_t l = 0; l < lights; ++l) {
      LightLink link;
      link.receiver = root;
      link.light = static_cast<std::uint32_t>(l);
      out.push_back(link);
    }
  }
  return out;
}

template <typename PolygonAt>
void DirectLight::disk_light(const Element& receiver, const PolygonAt& polygon_at,
                             std::span<const dvec3> shaft, double scale, Values& out) const {
  dvec3 corners[4], x[kMaxSamples];
  const int nc = hierarchy_.corners(receiver, corners);
  const int ns = hierarchy_.samples(receiver, x);
  const dvec3 n = hierarchy_.normal(receiver);
  const std::uint32_t face = hierarchy_.patch_of(receiver).surface;
  const bool sampled = visibility_ == VisibilityMode::Sampled;
  const ShaftCulling culling =
      cull_shaft(occluders_.shafts, std::span<const dvec3>(corners, static_cast<size_t>(nc)), face,
                 shaft, kNoFace, sampled ? kRayCrossover : std::numeric_limits<std::size_t>::max());
  if (culling.visibility == ShaftVisibility::hidden) return;
  std::vector<Triangle> candidates;
  if (!culling.truncated)
    for (std::uint32_t t : culling.candidates) candidates.push_back(occluders_.shafts.triangles[t]);
  for (int s = 0; s < ns; ++s) {
    const auto polygon = polygon_at(x[s]);
    const std::span<const dvec3> emitter(polygon.data(), polygon.size());
    FormFactorGradient f;
    if (culling.visibility == ShaftVisibility::clear) {
      f = form_factor_gradient(x[s], n, emitter);
    } else if (!sampled) {
      f = visible_form_factor_gradient(x[s], n, emitter, candidates);
    } else {
      const SampledVisibilityOptions options{rays_, static_cast<std::uint64_t>(s)};
      f = culling.truncated
              ? sampled_form_factor_gradient(x[s], n, emitter, *occluders_.rays, options, face)
              : sampled_form_factor_gradient(x[s], n, emitter, candidates, options);
    }
    // Rounding where occluders meet (the edges of a closed box), not light: it
    // would light the inside of the box.
    if (culling.visibility != ShaftVisibility::clear &&
        !(f.value > kRounding * form_factor(x[s], n, emitter)))
      continue;
    out.value[s] += scale * f.value;
    out.gradient[s] += scale * f.gradient;
  }
}

void DirectLight::point_or_spot(const Light& light, const Element& receiver, Values& out) const {
  dvec3 x[kMaxSamples];
  const int ns = hierarchy_.samples(receiver, x);
  const dvec3 n = hierarchy_.normal(receiver);
  const dvec3 axis = glm::normalize(light.direction);
  const dvec3& p = light.position;
  if (light.radius > 0.0) {
    const double r = light.radius;
    // The cone a sphere fills seen from x, as a disk through its centre.
    const auto disk_radius = [&](double distance) {
      if (!light.sphere) return r;
      const double d2 = std::max(distance * distance - r * r, 1e-4 * r * r);
      return r * distance / std::sqrt(d2);
    };
    const dvec3 centre = hierarchy_.centre(receiver);
    double widest = 0.0;
    for (int s = 0; s < ns; ++s) widest = std::max(widest, disk_radius(glm::length(x[s] - p)));
    const DiskPolygon shaft = disk_polygon(p, glm::normalize(centre - p), 1.5 * widest);
    disk_light(
        receiver,
        [&](const dvec3& at) {
          return disk_polygon(p, glm::normalize(at - p), disk_radius(glm::length(at - p)));
        },
        shaft, 1.0 / (r * r), out);
  } else {
    dvec3 corners[4];
    const int nc = hierarchy_.corners(receiver, corners);
    const dvec3 centre = hierarchy_.centre(receiver);
    const auto end = triangle_around(p, glm::normalize(centre - p), 1e-6 * glm::length(centre - p));
    bool blocked[kMaxSamples] = {};
    shadow_rays(
        occluders_, std::span<const dvec3>(corners, static_cast<size_t>(nc)),
        hierarchy_.patch_of(receiver).surface, std::span<const dvec3>(x, static_cast<size_t>(ns)),
        end, visibility_ == VisibilityMode::Sampled, [&](const dvec3&) { return p; }, blocked);
    for (int s = 0; s < ns; ++s) {
      const dvec3 d = p - x[s];
      const double d2 = glm::dot(d, d), nd = glm::dot(n, d);
      if (!(d2 > 0.0) || nd <= 0.0 || blocked[s]) continue;
      const double len = std::sqrt(d2);
      out.value[s] = nd / (d2 * len);
      out.gradient[s] = -n / (d2 * len) + 3.0 * nd * d / (d2 * d2 * len);
    }
  }
  if (light.kind != LightKind::Spot) return;
  for (int s = 0; s < ns; ++s) {
    const dvec3 w = x[s] - p;
    const double len = glm::length(w);
    if (!(len > 0.0)) continue;
    const dvec3 u = w / len;
    const double c = glm::dot(axis, u);
    const SpotFactor f = spot_factor(light, c);
    const dvec3 dc = (axis - c * u) / len;
    out.gradient[s] = f.value * out.gradient[s] + out.value[s] * f.derivative * dc;
    out.value[s] *= f.value;
  }
}

void DirectLight::sun(const Light& light, const Element& receiver, Values& out) const {
  const dvec3 travel = glm::normalize(light.direction);
  if (light.angle < kPointSun) {
    dvec3 x[kMaxSamples];
    const int ns = hierarchy_.samples(receiver, x);
    const double c = -glm::dot(hierarchy_.normal(receiver), travel);
    if (c <= 0.0) return;
    dvec3 corners[4];
    const int nc = hierarchy_.corners(receiver, corners);
    const auto end = triangle_around(hierarchy_.centre(receiver) - far_ * travel, travel,
                                     hierarchy_.diameter(receiver));
    bool blocked[kMaxSamples] = {};
    shadow_rays(
        occluders_, std::span<const dvec3>(corners, static_cast<size_t>(nc)),
        hierarchy_.patch_of(receiver).surface, std::span<const dvec3>(x, static_cast<size_t>(ns)),
        end, visibility_ == VisibilityMode::Sampled,
        [&](const dvec3& at) { return at - far_ * travel; }, blocked);
    for (int s = 0; s < ns; ++s)
      if (!blocked[s]) out.value[s] = c;
    return;
  }
  const double half = 0.5 * light.angle;
  const double radius = far_ * std::tan(half);
  const DiskPolygon shaft = disk_polygon(hierarchy_.centre(receiver) - far_ * travel, travel,
                                         radius + hierarchy_.diameter(receiver));
  const double sin_half = std::sin(half);
  disk_light(
      receiver, [&](const dvec3& at) { return disk_polygon(at - far_ * travel, travel, radius); },
      shaft, 1.0 / (sin_half * sin_half), out);
}

void DirectLight::sky(const Element& receiver, Values& out) const {
  dvec3 corners[4];
  const int nc = hierarchy_.corners(receiver, corners);
  const dvec3 n = hierarchy_.normal(receiver);
  for (const auto& face : sky_) {
    bool in_front = false;
    for (const dvec3& c : face)
      for (int k = 0; k < nc; ++k) in_front |= glm::dot(n, c - corners[k]) > 0.0;
    if (!in_front) continue;
    disk_light(
        receiver, [&](const dvec3&) { return face; },
        std::span<const dvec3>(face.data(), face.size()), 1.0, out);
  }
}

double DirectLight::probe(const Light& light, const Element& receiver) const {
  if (light.kind == LightKind::Sky) return 0.0;
  dvec3 c[4];
  const int nc = hierarchy_.corners(receiver, c);
  const dvec3 n = hierarchy_.normal(receiver);
  const std::uint32_t face = hierarchy_.patch_of(receiver).surface;
  const dvec3 axis = glm::normalize(light.direction);
  double largest = 0.0;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const dvec3 x = grid_point(c, nc, i, j, 4);
      double value = 0.0;
      dvec3 to;
      if (light.kind == LightKind::Sun) {
        value = std::max(0.0, -glm::dot(n, axis));
        to = x - far_ * axis;
      } else {
        const dvec3 d = light.position - x;
        const double d2 = glm::dot(d, d);
        if (!(d2 > 0.0)) continue;
        const double len = std::sqrt(d2);
        value = std::max(0.0, glm::dot(n, d)) / (d2 * len) *
                spot_factor(light, glm::dot(axis, -d / len)).value;
        to = light.position;
      }
      if (value > largest && !occluders_.rays->occluded(x, to, face)) largest = value;
    }
  }
  return largest;
}

bool DirectLight::evaluate(LightLink& link) const {
  const Element& receiver = hierarchy_.element(link.receiver);
  const Light& light = hierarchy_.scene().lights[link.light];
  Values values;
  switch (light.kind) {
    case LightKind::Point:
    case LightKind::Spot:
      point_or_spot(light, receiver, values);
      break;
    case LightKind::Sun:
      sun(light, receiver, values);
      break;
    case LightKind::Sky:
      sky(receiver, values);
      break;
  }
  dvec3 x[kMaxSamples];
  const int ns = hierarchy_.samples(receiver, x);
  double value[kMaxSamples], largest = 0.0;
  for (int s = 0; s < ns; ++s) {
    value[s] = std::max(0.0, values.value[s]);
    link.value[static_cast<size_t>(s)] = static_cast<float>(value[s]);
    largest = std::max(largest, value[s]);
  }
  const double missed = probe(light, receiver);
  link.missed = missed > 2.0 * largest ? static_cast<float>(missed) : 0.0f;
  if (!(largest > 0.0) && !(link.missed > 0.0f)) return false;
  link.oracle = 0.0f;
  if (!(largest > 0.0)) return true;
  const LinkSamples samples{std::span<const dvec3>(x, static_cast<size_t>(ns)),
                            std::span<const double>(value, static_cast<size_t>(ns)),
                            std::span<const dvec3>(values.gradient, static_cast<size_t>(ns)),
                            hierarchy_.normal(receiver),
                            receiver.area,
                            hierarchy_.diameter(receiver),
                            resolvable_size(hierarchy_.scene().total_area)};
  link.oracle = static_cast<float>(oracle_geometry(oracle_, samples) / geometric_scale_);
  return true;
}

}  // namespace radiosity
