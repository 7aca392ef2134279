// Sampled visibility (see sampled_visibility.h).
#include "core/sampled_visibility.h"

#include <algorithm>
#include <cmath>

namespace radiosity {
namespace {

// SplitMix64: small, fast, and good enough to jitter strata.
struct SplitMix64 {
  std::uint64_t state;
  std::uint64_t next() {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
};

}  // namespace

EmitterSamples sample_emitter(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                              const SampledVisibilityOptions& options) {
  EmitterSamples out;
  const int count = std::max(1, options.rays);
  if (emitter.size() < 3) return out;
  // Fan of triangles from v0, chosen by the first parameter in proportion to area.
  const std::size_t fan = emitter.size() - 2;
  std::vector<double> cumulative(fan);
  dvec3 normal(0.0);
  double area = 0.0;
  for (std::size_t i = 0; i < fan; ++i) {
    const dvec3 c = glm::cross(emitter[i + 1] - emitter[0], emitter[i + 2] - emitter[0]);
    normal += c;
    area += 0.5 * glm::length(c);
    cumulative[i] = area;
  }
  if (!(area > 0.0)) return out;
  normal = glm::normalize(normal);

  // A (0,2)-sequence (the first two dimensions of Sobol's sequence) with a random
  // digital shift: every power-of-two prefix is stratified over all elementary
  // rectangles of the unit square, so shadow edges in any direction are sampled
  // evenly (error about N^-3/4, where N-rooks or random points give N^-1/2).
  SplitMix64 rng{options.seed * 0x2545F4914F6CDD1Dull + 1};
  const auto shift_u = static_cast<std::uint32_t>(rng.next() >> 32);
  const auto shift_v = static_cast<std::uint32_t>(rng.next() >> 32);
  const auto jitter = [&](std::uint32_t bits) {
    // The 32 digits of the net, plus uniform jitter below them.
    return (static_cast<double>(bits) + rng.uniform()) * 0x1.0p-32;
  };

  out.points.reserve(static_cast<std::size_t>(count));
  out.weights.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const auto index = static_cast<std::uint32_t>(k);
    std::uint32_t bits_u = 0, bits_v = 0, direction = 1u << 31;
    for (std::uint32_t i = index, bit = 0; i != 0; i >>= 1, ++bit) {
      if (i & 1u) {
        bits_u ^= 1u << (31 - bit);  // van der Corput: the bits of k reversed
        bits_v ^= direction;         // Sobol's second dimension (polynomial x + 1)
      }
      direction ^= direction >> 1;
    }
    double u = jitter(bits_u ^ shift_u);
    const double v = jitter(bits_v ^ shift_v);
    // Pick the fan triangle and rescale u within it (keeps the stratification).
    const double target = u * area;
    std::size_t t = 0;
    while (t + 1 < fan && cumulative[t] < target) ++t;
    const double lo = t == 0 ? 0.0 : cumulative[t - 1];
    u = std::clamp((target - lo) / (cumulative[t] - lo), 0.0, 1.0);
    // Area-preserving map of the unit square to the triangle.
    const double su = std::sqrt(u);
    const dvec3 p = emitter[0] + su * (1.0 - v) * (emitter[t + 1] - emitter[0]) +
                    su * v * (emitter[t + 2] - emitter[0]);
    const dvec3 d = p - r;
    const double d2 = glm::dot(d, d);
    const double cos_r = glm::dot(n, d), cos_e = -glm::dot(normal, d);
    out.points.push_back(p);
    out.weights.push_back(cos_r > 0.0 && cos_e > 0.0 && d2 > 0.0 ? cos_r * cos_e / (d2 * d2) : 0.0);
  }
  return out;
}

double visible_fraction(const EmitterSamples& samples, std::span<const std::uint8_t> blocked) {
  double total = 0.0, visible = 0.0;
  for (std::size_t i = 0; i < samples.weights.size(); ++i) {
    total += samples.weights[i];
    if (!blocked[i]) visible += samples.weights[i];
  }
  return total > 0.0 ? visible / total : 1.0;
}

double visible_fraction(const RayScene& scene, const dvec3& r, const EmitterSamples& samples,
                        std::uint32_t receiver_face, std::uint32_t emitter_face) {
  std::vector<std::uint8_t> blocked(samples.points.size(), 0);
  // Rays towards points with zero weight change nothing: do not cast them.
  std::vector<dvec3> targets;
  std::vector<std::size_t> index;
  for (std::size_t i = 0; i < samples.points.size(); ++i)
    if (samples.weights[i] > 0.0) {
      targets.push_back(samples.points[i]);
      index.push_back(i);
    }
  std::vector<std::uint8_t> hit(targets.size(), 0);
  scene.occluded(r, targets, hit, receiver_face, emitter_face);
  for (std::size_t j = 0; j < index.size(); ++j) blocked[index[j]] = hit[j];
  return visible_fraction(samples, blocked);
}

bool segment_hits_triangle(const dvec3& a, const dvec3& b, const Triangle& t) {
  const dvec3 d = b - a;
  const dvec3 e1 = t.v[1] - t.v[0], e2 = t.v[2] - t.v[0];
  const dvec3 p = glm::cross(d, e2);
  const double det = glm::dot(e1, p);
  if (det == 0.0) return false;  // segment parallel to the triangle's plane
  const double inv = 1.0 / det;
  const dvec3 s = a - t.v[0];
  const double u = glm::dot(s, p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const dvec3 q = glm::cross(s, e1);
  const double v = glm::dot(d, q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  const double h = glm::dot(e2, q) * inv;
  return h > 1e-9 && h < 1.0 - 1e-9;
}

double visible_fraction(std::span<const Triangle> candidates, const dvec3& r,
                        const EmitterSamples& samples) {
  std::vector<std::uint8_t> blocked(samples.points.size(), 0);
  // Neighbouring samples tend to be blocked by the same triangle: try the last
  // blocker first.
  std::size_t last = 0;
  for (std::size_t i = 0; i < samples.points.size(); ++i) {
    if (samples.weights[i] <= 0.0) continue;
    if (!candidates.empty() && segment_hits_triangle(r, samples.points[i], candidates[last])) {
      blocked[i] = 1;
      continue;
    }
    for (std::size_t t = 0; t < candidates.size(); ++t)
      if (t != last && segment_hits_triangle(r, samples.points[i], candidates[t])) {
        blocked[i] = 1;
        last = t;
        break;
      }
  }
  return visible_fraction(samples, blocked);
}

FormFactorGradient sampled_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                const RayScene& scene,
                                                const SampledVisibilityOptions& options,
                                                std::uint32_t receiver_face,
                                                std::uint32_t emitter_face) {
  FormFactorGradient fg = form_factor_gradient(r, n, emitter);
  if (fg.value <= 0.0) return fg;
  const EmitterSamples samples = sample_emitter(r, n, emitter, options);
  const double fraction = visible_fraction(scene, r, samples, receiver_face, emitter_face);
  return {fraction * fg.value, fraction * fg.gradient};
}

FormFactorGradient sampled_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                std::span<const Triangle> candidates,
                                                const SampledVisibilityOptions& options) {
  FormFactorGradient fg = form_factor_gradient(r, n, emitter);
  if (fg.value <= 0.0 || candidates.empty()) return fg;
  const EmitterSamples samples = sample_emitter(r, n, emitter, options);
  const double fraction = visible_fraction(candidates, r, samples);
  return {fraction * fg.value, fraction * fg.gradient};
}

}  // namespace radiosity
