// Visible part of an emitter polygon as seen from a receiver point (Section 4.3,
// Figures 17-20): the emitter minus the central projections, from the point onto
// the emitter plane, of the occluder triangles, kept as convex pieces whose
// vertices remember what generates them, so that the exact gradient of the
// occluded form factor can be computed (eqs. 14-15).
//
// How (DESIGN.md section 4):
//  1. The emitter is clipped to the receiver's upper half-space (horizon points
//     act as fixed vertices, MATH.md section 2).
//  2. Each occluder triangle is clipped in 3D to the pyramid from the point
//     through the emitter (its side planes and the emitter plane): what remains
//     lies between the point and the emitter and projects inside the emitter,
//     bounded, even for occluders that reach behind the point or behind the emitter.
//  3. Its projection (a convex polygon) is subtracted from every visible piece by
//     successive half-plane clipping. The artificial cut edges between pieces
//     cancel in both F and its gradient. Two consecutive occluder triangles that
//     form a planar convex quad (a mesh quad split in two) are subtracted as one
//     quad, which saves the cuts along their diagonal.
// Every edge carries the 3D line that generates it (an emitter edge, an occluder
// edge, the trace of an occluder plane on the emitter plane, or the receiver's
// horizon); every vertex is the crossing of its two edges: intrinsic when the two
// lines meet in 3D (emitter vertex, occluder vertex, occluder edge piercing the
// emitter plane), apparent otherwise (lines s and t, eq. 14).
//
// Tolerances are relative to the emitter's size and the point's distance, so the
// result does not change when the scene is scaled. Domain: coordinates within
// kMaxCoordinate (core/scene.h), as a scene's are; the bindings refuse others
// (products of four lengths of 1e154 overflow: NaN anchors).
#pragma once

#include <span>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/triangle.h"
#include "radiosity/vec.h"

namespace radiosity {

// One convex piece of the visible region, counter-clockwise about the emitter's
// front normal, vertices on the emitter plane.
using VisiblePiece = std::vector<ContourVertex>;

struct VisiblePolygon {
  std::vector<VisiblePiece> pieces;
  // True when an occluder removed part of the emitter; the pieces then describe
  // the visible region. When false, `pieces` holds the horizon-clipped emitter.
  bool occluded = false;
  // True when the receiver sees no part of the emitter's front (behind it, on its
  // plane, the emitter below the horizon, or everything hidden).
  bool empty() const { return pieces.empty(); }
};

// The visible region of `emitter` (convex, counter-clockwise about its front
// normal, at least 3 vertices, non-degenerate) from point `r` with unit normal `n`,
// with `occluders` in the way. Occluders may be any triangles of the scene: those
// that cannot block (behind the emitter, behind the point, outside the pyramid,
// coplanar with the emitter or with the point) are skipped here.
VisiblePolygon visible_polygon(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                               std::span<const Triangle> occluders);

// Exact form factor of the visible part of the emitter and its gradient with
// respect to the receiver point: the sum over the convex pieces of the visible
// region. Always finite, F in [0, unoccluded F]. If `open` is given, it
// receives the unoccluded F (which the method computes anyway as its bound;
// the energy correction needs it too).
FormFactorGradient visible_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                std::span<const Triangle> occluders,
                                                double* open = nullptr);

// The visible form factor alone, without its gradient (cheaper: the pieces'
// vertices need no generating lines); `open` as above.
double visible_form_factor(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                           std::span<const Triangle> occluders, double* open = nullptr);

// The same for several parts of one emitter at once (the children of a split
// emitter element: convex, counter-clockwise, on the emitter's plane, inside
// it): the visible region of the whole emitter is computed once, with
// occluders that cover all the parts, and clipped to each part. out[i] is the
// visible form factor of parts[i]; equal to one call per part up to rounding.
// open[i], if `open` is not empty, receives part i's unoccluded F.
void visible_form_factor_gradient_parts(const dvec3& r, const dvec3& n,
                                        std::span<const dvec3> emitter,
                                        std::span<const std::span<const dvec3>> parts,
                                        std::span<const Triangle> occluders,
                                        std::span<FormFactorGradient> out,
                                        std::span<double> open = {});

// The emitters this code is exact for: planar and convex, with no repeated
// vertex (an edge of zero length made every visible piece NaN). nullptr if
// `polygon` is one, else what is wrong ("is not planar", ...), for a message.
const char* planar_convex_problem(std::span<const dvec3> polygon);

}  // namespace radiosity
