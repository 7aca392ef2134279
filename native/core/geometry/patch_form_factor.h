// Exact patch-to-patch (area-to-area) form factor of two unoccluded convex
// polygons, in double precision.
//
// Method. Each polygon is first clipped to the other's front half-space, so the
// signed integrand cos(theta_p) cos(theta_q) / (pi r^2) is non-negative on what
// is left and Stokes' theorem applies to it as it stands:
//  - Near pairs use the contour form (Mitalas and Stephenson; Schroeder and
//    Hanrahan 1993): A_p F_pq = -(1/2 pi) sum over edge pairs (u_i . u_j)
//    int_i int_j ln r. The inner edge integral is closed-form; the outer one is
//    numerical and adaptive (tanh-sinh next to points where the edges touch or
//    nearly do, whose log-singular derivative defeats polynomial rules;
//    Gauss-Kronrod elsewhere), split where the other edge comes closest.
//    Coordinates are local and scaled to O(1): the ln(scale) term cancels over
//    closed contours but not in rounding.
//  - Far pairs (gap >= 3 radii of the smaller polygon), where the contour form
//    loses digits to cancellation (terms ~ L^2 ln d, result ~ L^4 / d^2), use
//    Gauss quadrature of the point kernel `form_factor` over the smaller
//    polygon (bilinear map for quads, collapsed-square fan triangles
//    otherwise), whose integrand is analytic there; the order follows the gap.
//    Each polygon keeps its own local origin, so an offset changes nothing
//    beyond the rounding of the input itself.
//  - Near pairs of very different sizes (radii more than 8 apart) have the
//    larger polygon cut around the smaller: pieces beyond a square of
//    half-width 4 radii about it are far pairs, the square's part a contour
//    form of like sizes (the contour form alone loses digits in proportion to
//    the ratio: F = 3.5e12 for a 1.5e-14 polygon on a 0.25 one, fuzzing).
// Same conventions as form_factor.h: planar convex polygons, counter-clockwise
// about their front normals; tolerances relative to the polygons' size.
#pragma once

#include <span>

#include "radiosity/vec.h"

namespace radiosity {

// F from receiver polygon p to emitter polygon q: (1/A_p) * integral over p and q of
// cos(theta_p) cos(theta_q) / (pi r^2), counting only the parts of each polygon in
// front of the other's plane (each polygon is clipped to the other's front
// half-space first), no occluders. Both convex, counter-clockwise about their front
// normals, 3 to 16 vertices (more throws std::invalid_argument), coordinates
// within kMaxCoordinate (scene.h; beyond, products overflow). Returns 0 when
// nothing faces, for degenerate polygons and for non-finite input. Accurate to about
// 1e-6 relative (1e-10 typical), including contact (shared edges or vertices),
// coplanar polygons (0) and far-apart ones. `tolerance` sets the relative error
// aimed at for far-apart pairs (fewer quadrature points when larger).
double patch_form_factor(std::span<const dvec3> p, std::span<const dvec3> q,
                         double tolerance = 1e-12);

}  // namespace radiosity
