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

// The receiver's samples of one link: form factor and its gradient at each.
struct LinkSamples {
  std::span<const dvec3> position;
  std::span<const double> value;
  std::span<const dvec3> gradient;  // may be empty for the Standard oracle
  dvec3 normal{0.0};                // receiver normal (for tangential projection)
  double area = 0.0;                // receiver area
  double diameter = 0.0;            // receiver diameter
};

// Geometric part of the criterion, for unit rho_p L_q.
double oracle_geometry(Oracle oracle, const LinkSamples& samples);

// The perceptual criterion R = k max(r_ij, r_ji) for values B and gradients G in
// the same units (eqs. 25-28 with the corrections of MATH.md s4): slopes along
// the segment between samples, k from unit tangential gradients, and k_ij = 1
// where a gradient is too small to have a direction.
double perceptual_criterion(std::span<const dvec3> position, std::span<const double> value,
                            std::span<const dvec3> gradient, const dvec3& normal, double diameter);

// The oracle's scale in a scene, so thresholds are relative (DESIGN s3): with
// reference radiance L_ref and total area A, Standard divides by L_ref A,
// Perceptual by L_ref, Gradient by L_ref sqrt(A). The geometric part (A, 1,
// sqrt(A)) is applied when a link is made, so links store a dimensionless value.
double oracle_scale(Oracle oracle, double reference_radiance, double total_area);
double oracle_geometric_scale(Oracle oracle, double total_area);

}  // namespace radiosity
