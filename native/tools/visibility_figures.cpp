// Reproduces the experiment of the source's Section 4.3.1 (Figures 21-25): an
// emitter, an occluder and a receiver plane, all parallel; the occluder aligned
// with the emitter or turned 45 degrees; a large or a small emitter. For each of
// the four scenes it writes images of F and of |grad F| over the receiver plane
// (the gradient's part in the plane, the one that shows on it):
//
//   figNN_a_form_factor.png      F, colour map, shaded as a relief
//   figNN_b_gradient.png         |grad F|, the same way
//   figNN_b_gradient_events.png  the same with the predicted discontinuity lines
//                                drawn over it (red: emitter vertex behind an
//                                occluder edge, EV; blue: occluder vertex against
//                                an emitter edge, VE; where an EV and a VE line
//                                coincide, edges are parallel: a D1 event)
//
// Shading a relief makes creases visible: a slope discontinuity of the plotted
// function (a D1 crease of F, a D2 crease of |grad F|) is a jump in brightness.
//
// Geometry (Figure 21): receiver plane z = 0 (normal +z, shown over [-1.6, 1.6]^2),
// occluder a 0.6 x 0.6 square at z = 1, emitter a square at z = 2 facing down,
// side 1 (large) or 0.25 (small); occluder edges parallel to the emitter's
// (aligned) or turned 45 degrees.
//
// What they show (512 x 512, `make figures`):
//  - fig22, 45 degrees, large emitter: no umbra (F >= 0.003), a smooth
//    depression of F under the occluder. |grad F| is creased along straight
//    lines, exactly on the predicted EV (diagonal) and VE (axis-aligned) lines:
//    second-order (D2) discontinuities, the source's Figure 22b.
//  - fig23, 45 degrees, small emitter: a diamond umbra (F = 0) inside a narrow
//    penumbra; |grad F| is zero in the umbra and concentrated in the band, with
//    sharp creases at the band's edges and a ridge along its middle, where the
//    occluder edge passes two emitter corners at once (two D2 events on one line).
//  - fig24, aligned, large emitter: a small square umbra; F itself shows faint
//    creases along a cross and a square of lines where occluder and emitter edges
//    line up (EV and VE lines coincide: D1), and |grad F| jumps across them.
//  - fig25, aligned, small emitter: square umbra and penumbra band bounded by D1
//    lines; |grad F| is discontinuous there, and the corner squares where two
//    penumbrae overlap stand out, bounded by D1 lines too.
// Exactly on an event line the gradient returned is one of its one-sided limits
// (checked against one-sided differences); everywhere else it matches central
// differences to 5e-7 or better on these grids.
//
// Usage: visibility_figures OUTPUT_DIR [RESOLUTION]
#include <OpenImageIO/imageio.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/visibility/visible_polygon.h"

namespace radiosity {
namespace {

struct Scene {
  std::string name;
  std::string caption;
  std::vector<dvec3> emitter;   // at z = 2, facing down
  std::vector<dvec3> occluder;  // square at z = 1 (its outline)
  std::vector<Triangle> occluder_triangles;
};

// A square of side `side` at height z, turned by `angle` about the z axis,
// counter-clockwise about `facing`'s sign of z.
std::vector<dvec3> square(double side, double z, double angle, bool facing_down) {
  std::vector<dvec3> out;
  for (int i = 0; i < 4; ++i) {
    const double t = angle + kPi / 4.0 + i * kPi / 2.0;
    out.push_back({side / std::sqrt(2.0) * std::cos(t), side / std::sqrt(2.0) * std::sin(t), z});
  }
  if (facing_down) std::reverse(out.begin(), out.end());
  return out;
}

Scene make_scene(std::string name, std::string caption, double emitter_side,
                 double occluder_angle) {
  Scene s;
  s.name = std::move(name);
  s.caption = std::move(caption);
  s.emitter = square(emitter_side, 2.0, 0.0, true);
  s.occluder = square(0.6, 1.0, occluder_angle, false);
  s.occluder_triangles = {Triangle{{s.occluder[0], s.occluder[1], s.occluder[2]}},
                          Triangle{{s.occluder[0], s.occluder[2], s.occluder[3]}}};
  return s;
}

// Receiver plane z = 0, normal +z, over [-extent, extent]^2.
constexpr double kExtent = 1.6;

struct Field {
  int size = 0;
  std::vector<double> value;  // row-major, row 0 at +y (top of the image)
  double at(int x, int y) const { return value[static_cast<std::size_t>(y) * size + x]; }
};

dvec3 receiver_point(int x, int y, int size) {
  const double u = (x + 0.5) / size, v = (y + 0.5) / size;
  return {kExtent * (2.0 * u - 1.0), kExtent * (1.0 - 2.0 * v), 0.0};
}

void evaluate(const Scene& s, int size, Field& f, Field& grad) {
  f.size = grad.size = size;
  f.value.assign(static_cast<std::size_t>(size) * size, 0.0);
  grad.value = f.value;
  const dvec3 n(0.0, 0.0, 1.0);
  tbb::parallel_for(0, size, [&](int y) {
    for (int x = 0; x < size; ++x) {
      const FormFactorGradient fg = visible_form_factor_gradient(receiver_point(x, y, size), n,
                                                                 s.emitter, s.occluder_triangles);
      const std::size_t i = static_cast<std::size_t>(y) * size + x;
      f.value[i] = fg.value;
      grad.value[i] = std::hypot(fg.gradient.x, fg.gradient.y);
    }
  });
}

// A perceptually ordered colour map (viridis, 9 control points).
dvec3 colour_map(double t) {
  static const std::array<dvec3, 9> stops{{{0.267, 0.005, 0.329},
                                           {0.283, 0.141, 0.458},
                                           {0.254, 0.265, 0.530},
                                           {0.207, 0.372, 0.553},
                                           {0.164, 0.471, 0.558},
                                           {0.128, 0.567, 0.551},
                                           {0.135, 0.659, 0.518},
                                           {0.267, 0.749, 0.441},
                                           {0.993, 0.906, 0.144}}};
  t = std::clamp(t, 0.0, 1.0) * (stops.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(t), stops.size() - 2);
  const double w = t - static_cast<double>(i);
  return (1.0 - w) * stops[i] + w * stops[i + 1];
}

using Image = std::vector<float>;  // RGB, row-major

// Colour by value, brightness by a light raking over the relief z = height * value.
Image shaded_relief(const Field& f) {
  const int n = f.size;
  const auto [lo, hi] = std::minmax_element(f.value.begin(), f.value.end());
  const double range = std::max(*hi - *lo, 1e-300);
  const double height = 0.35 * n;  // relief height in pixels for the full range
  const dvec3 light = glm::normalize(dvec3(-1.0, 1.0, 1.2));
  Image img(static_cast<std::size_t>(n) * n * 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const double t = (f.at(x, y) - *lo) / range;
      const int x0 = std::max(x - 1, 0), x1 = std::min(x + 1, n - 1);
      const int y0 = std::max(y - 1, 0), y1 = std::min(y + 1, n - 1);
      const double dx = height * (f.at(x1, y) - f.at(x0, y)) / range / (x1 - x0);
      const double dy = height * (f.at(x, y0) - f.at(x, y1)) / range / (y1 - y0);  // +y is up
      const dvec3 normal = glm::normalize(dvec3(-dx, -dy, 1.0));
      const double shade = 0.3 + 0.7 * std::max(0.0, glm::dot(normal, light));
      const dvec3 c = colour_map(t) * shade;
      float* p = &img[(static_cast<std::size_t>(y) * n + x) * 3];
      p[0] = static_cast<float>(c.x);
      p[1] = static_cast<float>(c.y);
      p[2] = static_cast<float>(c.z);
    }
  return img;
}

// Central projection of point p from centre c onto the plane z = 0.
dvec3 project_to_receiver(const dvec3& c, const dvec3& p) {
  return c + (p - c) * (c.z / (c.z - p.z));
}

void draw_segment(Image& img, int n, const dvec3& a, const dvec3& b, const dvec3& colour) {
  const auto to_pixel = [&](const dvec3& p) {
    return dvec2((p.x / kExtent + 1.0) * 0.5 * n - 0.5, (1.0 - p.y / kExtent) * 0.5 * n - 0.5);
  };
  const dvec2 pa = to_pixel(a), pb = to_pixel(b);
  const int steps = static_cast<int>(std::ceil(glm::length(pb - pa) * 2.0)) + 1;
  for (int i = 0; i <= steps; ++i) {
    const dvec2 q = pa + (pb - pa) * (static_cast<double>(i) / steps);
    const int x = static_cast<int>(std::lround(q.x)), y = static_cast<int>(std::lround(q.y));
    if (x < 0 || y < 0 || x >= n || y >= n) continue;
    float* p = &img[(static_cast<std::size_t>(y) * n + x) * 3];
    for (int k = 0; k < 3; ++k) p[k] = static_cast<float>(0.35 * p[k] + 0.65 * colour[k]);
  }
}

// Lines on the receiver plane where the visible polygon changes structure:
// EV (an emitter vertex seen behind an occluder edge) and VE (an occluder
// vertex seen on an emitter edge), each the projection of the edge through the
// vertex. Parallel emitter and occluder edges make EV and VE lines coincide (D1).
void draw_events(Image& img, int n, const Scene& s) {
  const dvec3 red(1.0, 0.1, 0.1), blue(0.2, 0.5, 1.0);
  const std::size_t k = s.occluder.size(), m = s.emitter.size();
  for (const dvec3& e : s.emitter)
    for (std::size_t i = 0; i < k; ++i)
      draw_segment(img, n, project_to_receiver(e, s.occluder[i]),
                   project_to_receiver(e, s.occluder[(i + 1) % k]), red);
  for (const dvec3& o : s.occluder)
    for (std::size_t i = 0; i < m; ++i) {
      // Lines from the emitter edge's points through o, onto z = 0.
      const dvec3 a = o + (o - s.emitter[i]) * (o.z / (s.emitter[i].z - o.z));
      const dvec3 b = o + (o - s.emitter[(i + 1) % m]) * (o.z / (s.emitter[(i + 1) % m].z - o.z));
      draw_segment(img, n, a, b, blue);
    }
}

bool write_png(const std::filesystem::path& path, const Image& img, int n) {
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out) return false;
  const OIIO::ImageSpec spec(n, n, 3, OIIO::TypeDesc::UINT8);
  if (!out->open(path.string(), spec)) return false;
  // sRGB-ish encoding of the linear colours, so mid tones are not crushed.
  std::vector<unsigned char> bytes(img.size());
  for (std::size_t i = 0; i < img.size(); ++i)
    bytes[i] = static_cast<unsigned char>(std::lround(
        255.0 * std::pow(std::clamp(static_cast<double>(img[i]), 0.0, 1.0), 1.0 / 2.2)));
  const bool ok = out->write_image(OIIO::TypeDesc::UINT8, bytes.data());
  return out->close() && ok;
}

}  // namespace
}  // namespace radiosity

int main(int argc, char** argv) {
  using namespace radiosity;
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_DIR [RESOLUTION]\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  const int size = argc > 2 ? std::clamp(std::atoi(argv[2]), 16, 4096) : 512;
  std::filesystem::create_directories(dir);
  const double turned = kPi / 4.0;
  const std::vector<Scene> scenes{
      make_scene("fig22", "45 degree occluder, large emitter", 1.0, turned),
      make_scene("fig23", "45 degree occluder, small emitter", 0.25, turned),
      make_scene("fig24", "aligned occluder, large emitter", 1.0, 0.0),
      make_scene("fig25", "aligned occluder, small emitter", 0.25, 0.0),
  };
  for (const Scene& s : scenes) {
    Field f, grad;
    evaluate(s, size, f, grad);
    const auto [fmin, fmax] = std::minmax_element(f.value.begin(), f.value.end());
    const auto [gmin, gmax] = std::minmax_element(grad.value.begin(), grad.value.end());
    Image events = shaded_relief(grad);
    draw_events(events, size, s);
    const bool ok = write_png(dir / (s.name + "_a_form_factor.png"), shaded_relief(f), size) &&
                    write_png(dir / (s.name + "_b_gradient.png"), shaded_relief(grad), size) &&
                    write_png(dir / (s.name + "_b_gradient_events.png"), events, size);
    if (!ok) {
      std::fprintf(stderr, "cannot write images to %s: %s\n", dir.string().c_str(),
                   OIIO::geterror().c_str());
      return 1;
    }
    std::printf("%s (%s): F in [%.4g, %.4g], |grad F| in [%.4g, %.4g]\n", s.name.c_str(),
                s.caption.c_str(), *fmin, *fmax, *gmin, *gmax);
  }
  std::printf("wrote %zu images to %s\n", 3 * scenes.size(), dir.string().c_str());
  return 0;
}
