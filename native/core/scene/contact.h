// Contact meshing: where a face lies on another face, near its plane, or
// passes through it, the receiving face is split along the outline of what
// covers it and along the lines where the two meet (the order-zero
// discontinuities of the radiance: Baum, Rushmeier and Winget 1989 meshed
// along surface intersections; Lischinski, Tampieri and Greenberg 1992 call
// them D0), so that no element straddles them. Otherwise an element of a
// ceiling under a light a hair below it averages the bright pocket behind the
// light with the open ceiling around it and sends that into the room (the
// Cornell box came out 22 to 65 % too bright), and a plate through the wall
// of a closed lamp box carries the lamp's light out.
//
// What counts as contact, for a patch P and another patch Q (of another face):
// - Q parallel to P (within 5 degrees) and no further from P's plane than a
//   tenth of the smaller one's diameter: P is split along the outline of Q's
//   projection onto it (the floor under a box, the ceiling behind a light, the
//   wall behind a picture, down to a light 1 cm under a ceiling), if that
//   projection overlaps P: the next face of a smooth mesh, bent by a degree,
//   only borders P and is no cover;
// - Q passes through P's plane: P is split along the segment they share
//   (a plate through a wall);
// - an edge of Q touches P's plane (within a hundredth of Q's diameter): P is
//   split along that edge's projection (the feet of a box's walls on a floor).
// Each cut runs across the piece of P it passes through, so the pieces stay
// convex; cuts that would leave a piece thinner than 1e-4 of P's diameter
// are skipped, and so are faces (or lines of contact) smaller than 5 % of
// P's diameter that do not emit (a chair leg on a floor). Where Q lies in P's plane (within 1e-5 of
// their diameters, or 1e-6 of the scene's), the two coincide there: the coinciding pieces become
// one patch, with one side per direction (the emitting one, else the first
// face's), so a doubled wall sends its light once; the pairs facing the same
// way are listed in Scene::coincident.
//
// Candidate pairs come from a bounding volume hierarchy over the patches:
// n log n in the faces, plus the pairs that really touch.
#pragma once

#include "radiosity/scene.h"

namespace radiosity {

// Splits and merges `scene.patches` as described above; updates
// `scene.coincident` and `scene.split_faces`.
void mesh_contacts(Scene& scene);

}  // namespace radiosity
