// The emitter-side shape of a link: a coarse emitter whose radiance varies
// sends, along a link, its radiance weighted by how well each part of it sees
// the receiver (emitter_shape.h).
#include "core/hierarchy/emitter_shape.h"

#include <gtest/gtest.h>

#include "core/geometry/form_factor.h"
#include "radiosity/scene.h"

namespace radiosity {
namespace {

// A unit floor (facing +z) and a small wall standing near its x = 1 edge,
// facing back over the floor (-x).
Scene floor_and_wall(double gap) {
  const std::vector<double> positions = {0,   0,    0,       1,   0,       0,       1,    1,
                                         0,   0,    1,       0,   1 + gap, 0.4,     0.05, 1 + gap,
                                         0.4, 0.25, 1 + gap, 0.6, 0.25,    1 + gap, 0.6,  0.05};
  const std::vector<std::int64_t> faces = {0, 1, 2, 3, 4, 5, 6, 7};
  const std::vector<std::int64_t> sizes = {4, 4};
  const std::vector<double> reflectance = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
  const std::vector<double> emission = {1, 1, 1, 0, 0, 0};
  const std::vector<std::uint8_t> two_sided = {0, 0};
  return make_scene({positions, faces, sizes, reflectance, emission, two_sided, {}, {}, {}});
}

// Splits every leaf of `root` `levels` times.
void split(Hierarchy& h, std::int32_t root, int levels) {
  std::vector<std::int32_t> leaves{root};
  for (int l = 0; l < levels; ++l) {
    std::vector<std::int32_t> next;
    for (std::int32_t e : leaves) {
      const std::int32_t first = h.subdivide(e);
      for (int c = 0; c < 4; ++c) next.push_back(first + c);
    }
    leaves = next;
  }
}

struct Sent {
  double shaped, uniform, exact;
};

// What the floor, split once, sends towards the wall with radiance(x, y) on
// its four children.
Sent floor_sends(double gap, const std::function<double(double, double)>& radiance) {
  const Scene scene = floor_and_wall(gap);
  Hierarchy h(scene);
  const std::int32_t floor = h.root(0, 0), wall = h.root(1, 0);
  split(h, floor, 1);
  std::vector<Rgb> source(h.elements().size(), Rgb(0.0));
  double average = 0.0;
  for (size_t i = 0; i < h.elements().size(); ++i) {
    const Element& e = h.elements()[i];
    if (e.patch != 0 || !e.is_leaf()) continue;
    const dvec3 c = h.centre(e);
    source[i] = Rgb(radiance(c.x, c.y));
    average += source[i].x * e.area;
  }
  source[static_cast<size_t>(floor)] = Rgb(average);  // unit area
  dvec3 wall_corners[4];
  h.corners(h.element(wall), wall_corners);
  const EmitterShape shape = emitter_shape(h, h.element(floor), wall_corners);
  // Midpoint quadrature of the children's radiance weighted by the point form factor.
  const int n = 400;
  double weighted = 0.0, total = 0.0;
  for (int i = 0; i < n; ++i) {
    for (int j = 0; j < n; ++j) {
      const double x = (i + 0.5) / n, y = (j + 0.5) / n;
      const double f = form_factor(dvec3(x, y, 0), dvec3(0, 0, 1), wall_corners);
      const double child_x = x < 0.5 ? 0.25 : 0.75, child_y = y < 0.5 ? 0.25 : 0.75;
      weighted += f * radiance(child_x, child_y);
      total += f;
    }
  }
  return {sent_radiance(h, floor, source, shape).x, average, weighted / total};
}

TEST(EmitterShape, UniformRadianceIsSentUnchanged) {
  const Sent s = floor_sends(0.05, [](double, double) { return 2.0; });
  EXPECT_NEAR(s.shaped, 2.0, 1e-12);
}

TEST(EmitterShape, RadianceGrowingTowardsTheReceiverSendsMore) {
  for (double gap : {0.05, 0.3, 1.0}) {
    const Sent s = floor_sends(gap, [](double x, double) { return 1.0 + 3.0 * x * x; });
    SCOPED_TRACE(gap);
    EXPECT_GT(s.exact, s.uniform);
    EXPECT_LT(std::abs(s.shaped - s.exact), 0.25 * std::abs(s.uniform - s.exact))
        << "shaped " << s.shaped << " uniform " << s.uniform << " exact " << s.exact;
  }
}

}  // namespace
}  // namespace radiosity
