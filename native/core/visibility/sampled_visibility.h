// Sampled visibility, the cheaper mode (DESIGN.md section 4): stratified shadow
// rays from the receiver point to the emitter give the visible fraction of the
// form factor; F = fraction x unoccluded F, and the gradient is the unoccluded
// one scaled by the same fraction (it ignores how the shadow moves).
//
// The fraction is weighted by the point-to-point kernel cos cos / d^2 at each
// sample, so it converges to the exact F_visible / F_unoccluded as the ray count
// grows (an unweighted fraction would converge to the visible *area* fraction).
// Samples are uniform in area, stratified in both parameters (N-rooks over a
// fan of triangles), deterministic for a given seed.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/triangle.h"
#include "core/visibility/ray_scene.h"
#include "radiosity/vec.h"

namespace radiosity {

struct SampledVisibilityOptions {
  int rays = 64;
  std::uint64_t seed = 0;
};

// Points on the emitter and their kernel weights, seen from one receiver point.
struct EmitterSamples {
  std::vector<dvec3> points;
  std::vector<double> weights;  // cos_r cos_e / d^2, 0 where the point is not faced
};

EmitterSamples sample_emitter(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                              const SampledVisibilityOptions& options);

// Weighted visible fraction in [0, 1] (1 when no sample has weight), from flags
// (1 = blocked) of the segments r -> samples.points.
double visible_fraction(const EmitterSamples& samples, std::span<const std::uint8_t> blocked);

// Shadow rays through Embree, ignoring the link's own faces.
double visible_fraction(const RayScene& scene, const dvec3& r, const EmitterSamples& samples,
                        std::uint32_t receiver_face = kNoFace,
                        std::uint32_t emitter_face = kNoFace);

// Shadow rays tested in double precision against a link's candidate occluders
// (from shaft culling): no scene traversal, exact exclusion of the own faces.
double visible_fraction(std::span<const Triangle> candidates, const dvec3& r,
                        const EmitterSamples& samples);

// Segment (a, b) blocked by triangle t (Moller-Trumbore, open segment).
bool segment_hits_triangle(const dvec3& a, const dvec3& b, const Triangle& t);

// The unoccluded F and gradient times the visible fraction; `open`, if given,
// receives the unoccluded F.
FormFactorGradient sampled_form_factor_gradient(
    const dvec3& r, const dvec3& n, std::span<const dvec3> emitter, const RayScene& scene,
    const SampledVisibilityOptions& options, std::uint32_t receiver_face = kNoFace,
    std::uint32_t emitter_face = kNoFace, double* open = nullptr);

FormFactorGradient sampled_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                std::span<const Triangle> candidates,
                                                const SampledVisibilityOptions& options,
                                                double* open = nullptr);

}  // namespace radiosity
