// Sample placement (hierarchy.h): which elements' corner samples sit further
// in, off a contact line (Patch::edge_inset).
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

}  // namespace
}  // namespace radiosity
