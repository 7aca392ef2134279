#include "core/solve/oracle.h"

#include <algorithm>
#include <cmath>

namespace radiosity {

bool oracle_needs_gradient(Oracle oracle) { return oracle != Oracle::Standard; }

bool oracle_judges_by_gradients(Oracle oracle) {
  return oracle == Oracle::Perceptual || oracle == Oracle::Gradient;
}

namespace {

// A twentieth of sqrt(A): 45 cm in an 80 m2 room. Measured on the study's
// scenes against 1/60, 1/10 and 1/3 (and none): smaller lets thin shadows and
// hidden corners take the elements, larger leaves broad shading coarse.
constexpr double kResolvableFraction = 1.0 / 20.0;

dvec3 tangential(const dvec3& g, const dvec3& normal) { return g - normal * glm::dot(normal, g); }

}  // namespace

double perceptual_criterion(std::span<const dvec3> position, std::span<const double> value,
                            std::span<const dvec3> gradient, const dvec3& normal, double diameter) {
  const size_t n = position.size();
  double b_min = value[0], b_max = value[0], b_abs = 0.0;
  for (double b : value) {
    b_min = std::min(b_min, b);
    b_max = std::max(b_max, b);
    b_abs = std::max(b_abs, std::abs(b));
  }
  // Below this slope a gradient has no meaningful direction over the element.
  const double flat = 0.1 * (b_max - b_min) + 1e-9 * b_abs;
  double k = 0.0, r = 0.0;
  for (size_t i = 0; i < n; ++i) {
    const dvec3 gi = tangential(gradient[i], normal);
    const double gi_length = glm::length(gi);
    for (size_t j = i + 1; j < n; ++j) {
      const dvec3 gj = tangential(gradient[j], normal);
      const double gj_length = glm::length(gj);
      const dvec3 step = position[j] - position[i];
      const double d = glm::length(step);
      if (!(d > 0.0)) continue;
      const dvec3 e = step / d;
      // Tangent at i extrapolated to j, and at j back to i (eq. 26).
      const double r_ij = std::abs(value[i] + glm::dot(gi, e) * d - value[j]);
      const double r_ji = std::abs(value[j] - glm::dot(gj, e) * d - value[i]);
      r = std::max({r, r_ij, r_ji});
      // Linearity coefficient (eq. 27) on unit tangential gradients.
      const double k_ij = std::min(gi_length, gj_length) * diameter <= flat
                              ? 1.0
                              : 0.5 * (1.0 - glm::dot(gi / gi_length, gj / gj_length));
      k = std::max(k, k_ij);
    }
  }
  return k * r;  // eq. 28
}

double reconstruction_error(std::span<const dvec3> position, std::span<const double> value,
                            std::span<const dvec3> gradient, const dvec3& normal,
                            size_t value_only) {
  const size_t n = position.size(), with_tangent = n - std::min(value_only, n);
  // Tangent at i extrapolated to every other sample j (eq. 26's r_ij, r_ji).
  double r = 0.0;
  for (size_t i = 0; i < with_tangent; ++i) {
    const dvec3 gi = tangential(gradient[i], normal);
    for (size_t j = 0; j < n; ++j) {
      if (j != i)
        r = std::max(r, std::abs(value[i] + glm::dot(gi, position[j] - position[i]) - value[j]));
    }
  }
  // Never above the largest sample: tangents at a contact (a gradient without
  // bound, MATH.md s3) would claim errors far beyond any light the link brings.
  const double largest = *std::max_element(value.begin(), value.end());
  return std::min(0.5 * r, largest);
}

double resolvable_size(double total_area) { return kResolvableFraction * std::sqrt(total_area); }

double oracle_reference(Oracle oracle, double adaptation, double receiver_luminance) {
  if (oracle != Oracle::Noticeable) return adaptation;
  return kWeberFraction * (std::max(0.0, receiver_luminance) + kDarkFloor * adaptation);
}

double oracle_geometry(Oracle oracle, const LinkSamples& s) {
  const size_t n = s.value.size();
  switch (oracle) {
    case Oracle::Standard: {
      const auto [lo, hi] = std::minmax_element(s.value.begin(), s.value.end());
      return (*hi - *lo) * s.area;
    }
    case Oracle::Perceptual:
      return perceptual_criterion(s.position, s.value, s.gradient, s.normal, s.diameter);
    case Oracle::Gradient: {
      double delta = 0.0;
      for (size_t i = 0; i < n; ++i) {
        for (size_t j = i + 1; j < n; ++j) {
          delta = std::max(delta, glm::length(tangential(s.gradient[i] - s.gradient[j], s.normal)));
        }
      }
      return delta * s.area;
    }
    case Oracle::Noticeable: {
      // A feature narrower than the eye resolves shows with its contrast times
      // its width over the resolvable one (a line blurred over a wider band);
      // an element's width is its area over its diameter (times sqrt 2: the
      // side of a square), so a sliver counts as narrow however long it is.
      const double width = std::sqrt(2.0) * s.area / std::max(s.diameter, 1e-300);
      const double fade = s.resolvable_size > 0.0 ? std::min(1.0, width / s.resolvable_size) : 1.0;
      const double error =
          std::max({reconstruction_error(s.position, s.value, s.gradient, s.normal, s.value_only),
                    s.average_error, 0.5 * s.shadow_contrast});
      return error * fade;
    }
  }
  return 0.0;
}

double oracle_geometric_scale(Oracle oracle, double total_area) {
  return oracle_scale(oracle, 1.0, total_area);
}

double oracle_scale(Oracle oracle, double reference_radiance, double total_area) {
  switch (oracle) {
    case Oracle::Standard:
      return reference_radiance * total_area;
    case Oracle::Perceptual:
      return reference_radiance;
    case Oracle::Gradient:
      return reference_radiance * std::sqrt(total_area);
    case Oracle::Noticeable:
      return reference_radiance;
  }
  return 1.0;
}

}  // namespace radiosity
