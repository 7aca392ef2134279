// Contact meshing (contact.h): what counts as a cover of a face.
#include "core/scene/contact.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/scene/test_scenes.h"

namespace radiosity {
namespace {

bool any_inset_or_class(const Patch& p) {
  for (int k = 0; k < p.corner_count; ++k)
    if (p.edge_inset[static_cast<size_t>(k)] > 0.0f || p.corner_class[static_cast<size_t>(k)] != 0)
      return true;
  return false;
}

// Two unit faces of a smooth mesh meeting at an edge, the second bent up by
// two degrees: near-parallel and close, as a cover is, yet it only borders
// the first. Neither is cut, and no edge or corner is marked as a
// discontinuity (which inset every face of a subdivided Suzanne's samples
// and gave each occluded link of theirs the exact 3 x 3 grid). A square 1 cm
// over the first face does cover it: that face is cut around it, with insets.
TEST(Contact, AFaceThatOnlyBordersAnotherDoesNotCoverIt) {
  const double bend = 2.0 * 3.14159265358979323846 / 180.0;
  const auto bent_pair = [&](bool with_cover) {
    test::Arrays a;
    a.quad({dvec3(0, 0, 0), dvec3(1, 0, 0), dvec3(1, 1, 0), dvec3(0, 1, 0)}, 0.5, 0.0);
    const dvec3 far(1.0 + std::cos(bend), 0.0, std::sin(bend));
    a.quad({dvec3(1, 0, 0), far, far + dvec3(0, 1, 0), dvec3(1, 1, 0)}, 0.5, 0.0);
    if (with_cover) a.square(dvec3(0.3, 0.3, 0.01), 0.3, true, 0.5, 0.0);
    a.square(dvec3(0.0, 0.0, 2.0), 1.0, false, 0.0, 1.0);  // a lamp over them
    return a.scene();
  };
  const Scene plain = bent_pair(false);
  EXPECT_EQ(plain.split_faces, 0u);
  for (const Patch& p : plain.patches) EXPECT_FALSE(any_inset_or_class(p)) << p.surface;

  const Scene covered = bent_pair(true);
  EXPECT_EQ(covered.split_faces, 1u);
  bool inset = false;
  for (const Patch& p : covered.patches)
    if (p.surface == 0) inset |= any_inset_or_class(p);
  EXPECT_TRUE(inset);
}

}  // namespace
}  // namespace radiosity
