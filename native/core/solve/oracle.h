// Refinement oracles (DESIGN s6; Secchia eqs. 6, 18-20, 25-28): how much a link
// p <- q is worth refining. An oracle is a closed set, so adding one is a new
// enumerator and a new case in oracle_geometry().
//
// Every criterion is linear in the emitter's radiance and the receiver's
// reflectance, so a link stores only its geometric part (unit radiance and
// reflectance), computed once when the link is made; the solver multiplies by
// the brightness of rho_p L_q and divides by the oracle's scene scale.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

#include "radiosity/solve.h"
#include "radiosity/vec.h"

namespace radiosity {

bool oracle_needs_gradient(Oracle oracle);

// The perceptual and gradient oracles judge a link by how its gradients differ
// between samples, so they need the gradients exact visibility gives, with
// occlusion: shadow rays' gradients ignore occluders (faint_samples.h).
bool oracle_judges_by_gradients(Oracle oracle);

// The receiver's samples of one link: form factor and its gradient at each.
struct LinkSamples {
  std::span<const dvec3> position;
  std::span<const double> value;
  std::span<const dvec3> gradient;  // may be empty for the Standard oracle
  dvec3 normal{0.0};                // receiver normal (for tangential projection)
  double area = 0.0;                // receiver area
  double diameter = 0.0;            // receiver diameter
  // Smallest feature the viewer resolves (Noticeable; resolvable_size()).
  double resolvable_size = 0.0;
  // The last samples give values only: at a contact their gradient has no
  // bound (MATH.md s3), so no tangent starts there (Noticeable only).
  size_t value_only = 0;
  // How far the samples' average was from the exact patch form factor (what
  // the energy correction moved): light the samples miss, where the mesh would
  // put it in the wrong place (Noticeable only).
  double average_error = 0.0;
  // How much more of the emitter occluders hide at one sample than at another
  // (form factor): a shadow edge between them, beside which the light rises
  // towards the open value (Noticeable only).
  double shadow_contrast = 0.0;
};

// Geometric part of the criterion, for unit rho_p L_q.
double oracle_geometry(Oracle oracle, const LinkSamples& samples);

// The perceptual criterion R = k max(r_ij, r_ji) for values B and gradients G in
// the same units (eqs. 25-28 with the corrections of MATH.md s4): slopes along
// the segment between samples, k from unit tangential gradients, and k_ij = 1
// where a gradient is too small to have a direction.
double perceptual_criterion(std::span<const dvec3> position, std::span<const double> value,
                            std::span<const dvec3> gradient, const dvec3& normal, double diameter);

// Largest error of the linear reconstruction the mesh shows between samples,
// estimated from the same tangent extrapolations as eq. 26 (half the largest
// r_ij: the chord misses a quadratic by r / 4 and a step between samples by up
// to r / 2), without eq. 27's k: a slope that changes only in size is as
// visible as one that turns.
double reconstruction_error(std::span<const dvec3> position, std::span<const double> value,
                            std::span<const dvec3> gradient, const dvec3& normal,
                            size_t value_only = 0);

// Weber's law (Secchia s3.4.1): a difference is seen when it exceeds about 2 %
// of the radiance around it. Below a fifth of the adaptation level the eye (and
// the display's sRGB curve) sees relative differences less: the threshold
// stays at 2 % of that floor (kDarkFloor: sRGB's response to relative change
// at a tenth of the adaptation level, matched within 10 %).
inline constexpr double kWeberFraction = 0.02;
inline constexpr double kDarkFloor = 0.2;

// Size below which a feature's contrast fades: the smallest detail worth
// resolving, a fraction of the scene's scale sqrt(A) (kResolvableFraction).
double resolvable_size(double total_area);

// What a link's brightness x geometric part is divided by before it is
// compared with the threshold: the adaptation radiance for the source's
// oracles (thresholds relative to the scene's brightness); one just noticeable
// difference at the receiver's radiance for Noticeable.
double oracle_reference(Oracle oracle, double adaptation, double receiver_luminance);

// The oracle's scale in a scene, so thresholds are relative (DESIGN s3): with
// reference radiance L_ref and total area A, Standard divides by L_ref A,
// Perceptual by L_ref, Gradient by L_ref sqrt(A) (Noticeable: by one JND at
// the receiver when deciding, oracle_reference; 1 here). The geometric part (A, 1,
// sqrt(A)) is applied when a link is made, so links store a dimensionless value.
double oracle_scale(Oracle oracle, double reference_radiance, double total_area);
double oracle_geometric_scale(Oracle oracle, double total_area);

}  // namespace radiosity
