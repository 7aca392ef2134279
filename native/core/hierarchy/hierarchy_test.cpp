// Sample placement (hierarchy.h): which elements' corner samples sit further
// in, off a contact line (Patch::edge_inset); the area of a split quad's
// children and of its interpolant's parts.
#include "core/hierarchy/hierarchy.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

// Only elements with a corner on an inset edge have inset samples: the grid
// of visible shares (link_transport.cpp) is computed for those alone.
TEST(Hierarchy, OnlyElementsTouchingAnInsetEdgeSampleFurtherIn) {
  test::Arrays a;
  a.square(dvec3(0.0), 1.0, true, 0.5, 0.0);
  a.square(dvec3(0.0, 0.0, 1.0), 0.2, false, 0.0, 1.0);
  const Scene plain_scene = a.scene();
  Scene scene = a.scene();
  scene.patches[0].edge_inset[0] = 0.01f;  // the floor's edge along y = 0
  const Hierarchy plain(plain_scene);
  Hierarchy h(scene);
  const std::int32_t floor = h.root(0, 0);
  EXPECT_TRUE(h.samples_inset(h.element(floor)));
  EXPECT_FALSE(plain.samples_inset(plain.element(plain.root(0, 0))));

  const std::int32_t first = h.subdivide(floor);
  int touching = 0;
  for (std::int32_t c = first; c < first + 4; ++c) {
    const Element& child = h.element(c);
    dvec3 corners[4];
    h.corners(child, corners);
    // In the input's units: the scene works in its own frame (scene.h), on
    // a grid of 2^-32 of its diameter.
    bool on_edge = false;
    for (int k = 0; k < child.corner_count; ++k)
      on_edge |= std::abs(scene.frame.to_world(corners[k]).y) < 1e-9;
    EXPECT_EQ(h.samples_inset(child), on_edge) << c;
    touching += on_edge ? 1 : 0;

    // Inset samples sit further in than the millionth every corner moves.
    dvec3 x[kMaxSamples];
    h.samples(child, x);
    double lowest = 1.0;
    for (int k = 0; k < child.corner_count; ++k)
      lowest = std::min(lowest, scene.frame.to_world(x[k]).y);
    if (on_edge) {
      EXPECT_GT(lowest, 1e-3);
    }
  }
  EXPECT_EQ(touching, 2);
}

// Area of a planar polygon and its centroid's x (fan from the first corner).
struct Shape {
  double area = 0.0, centroid_x = 0.0;
};
Shape shape_of(const dvec3* c, int n) {
  Shape s;
  dvec3 up(0.0);
  for (int k = 1; k + 1 < n; ++k) up += glm::cross(c[k] - c[0], c[k + 1] - c[0]);
  up = glm::normalize(up);
  for (int k = 1; k + 1 < n; ++k) {
    const double a = 0.5 * glm::dot(glm::cross(c[k] - c[0], c[k + 1] - c[0]), up);
    s.area += a;
    s.centroid_x += a * (c[0].x + c[k].x + c[k + 1].x) / 3.0;
  }
  s.centroid_x /= s.area;
  return s;
}

// A floor piece cut around a rotated box is a quad but not a parallelogram:
// its children differ in area, and its interpolant's average weighs its wide
// end more. Counted as quarters, such a piece under a spot's pool took 3.6 %
// less of the spot's light than it received (issue 34).
class Trapezoid : public ::testing::Test {
 protected:
  Trapezoid() {
    a_.quad({dvec3(0, 0, 0), dvec3(4, 0, 0), dvec3(1, 1, 0), dvec3(0, 1, 0)}, 0.5, 0.0);
    a_.square(dvec3(0, 0, 1), 1.0, false, 0.0, 1.0);  // a light above it: a scene must emit
    scene_ = a_.scene();
  }
  test::Arrays a_;
  Scene scene_;
};

TEST_F(Trapezoid, ChildrenHaveTheAreaOfTheirCorners) {
  Hierarchy h(scene_);
  const std::int32_t root = h.root(0, 0);
  const std::int32_t first = h.subdivide(root);
  h.subdivide(first + 1);  // a grandchild level at the wide end
  double sum = 0.0, smallest = 1e300, largest = 0.0;
  for (std::int32_t c = first; c < first + 4; ++c) {
    const Element& child = h.element(c);
    dvec3 corners[4];
    h.corners(child, corners);
    EXPECT_NEAR(child.area, shape_of(corners, 4).area, 1e-12 * child.area) << c;
    sum += child.area;
    smallest = std::min(smallest, child.area);
    largest = std::max(largest, child.area);
  }
  EXPECT_NEAR(sum, h.element(root).area, 1e-12 * sum);
  EXPECT_GT(largest, 1.5 * smallest);  // unequal: quarters would be wrong
  const Element& wide = h.element(first + 1);
  double parts = 0.0;
  for (std::int32_t c = wide.first_child; c < wide.first_child + 4; ++c) parts += h.element(c).area;
  EXPECT_NEAR(parts, wide.area, 1e-12 * parts);
}

// A field linear in position is bilinear in the quad's parameters with no
// bubble, so the interpolant is exact and its area average is the field at
// the centroid (x: 1.4 of the trapezoid's 4, where the corners' mean is 1.25).
TEST_F(Trapezoid, AverageOfALinearFieldIsItsValueAtTheCentroid) {
  Hierarchy h(scene_);
  const std::int32_t root = h.root(0, 0);
  const std::int32_t first = h.subdivide(root);
  for (const std::int32_t e : {root, first, first + 1, first + 2, first + 3}) {
    const Element& x = h.element(e);
    dvec3 corners[4];
    h.corners(x, corners);
    std::array<Rgb, kMaxSamples> values{};
    for (int k = 0; k < 4; ++k) values[static_cast<size_t>(k)] = Rgb(corners[k].x);
    values[4] = Rgb(h.centre(x).x);
    const double expected = shape_of(corners, 4).centroid_x;
    EXPECT_NEAR(h.average(x, values).x, expected, 1e-12) << e;
  }
  const Element& r = h.element(root);
  dvec3 corners[4];
  h.corners(r, corners);
  const double mean_of_corners = 0.25 * (corners[0].x + corners[1].x + corners[2].x + corners[3].x);
  EXPECT_GT(std::abs(shape_of(corners, 4).centroid_x - mean_of_corners), 0.01);
}

}  // namespace
}  // namespace radiosity
