// Sampled visibility (see sampled_visibility.h).
#include "core/visibility/sampled_visibility.h"

#include <algorithm>
#include <cmath>

#include "core/geometry/random.h"

namespace radiosity {

namespace {

// Per-thread scratch of the functions below: a large scene's link samples
// call them millions of times, and allocating their buffers each time made
// malloc and free 4 % of a 5,000-face solve.
struct Scratch {
  EmitterSamples samples;
  std::vector<double> cumulative;
  std::vector<std::uint8_t> blocked, hit;
  std::vector<dvec3> targets;
  std::vector<std::size_t> index;
};

// Not inlined: see thread_workspace() in visible_polygon.cpp.
[[gnu::noinline]] Scratch& thread_scratch() {
  thread_local Scratch scratch;
  return scratch;
}

void sample_emitter_into(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                         const SampledVisibilityOptions& options, std::vector<double>& cumulative,
                         EmitterSamples& out) {
  out.points.clear();
  out.weights.clear();
  const int count = std::max(1, options.rays);
  if (emitter.size() < 3) return;
  // Fan of triangles from v0, chosen by the first parameter in proportion to area.
  const std::size_t fan = emitter.size() - 2;
  cumulative.resize(fan);
  dvec3 normal(0.0);
  double area = 0.0;
  for (std::size_t i = 0; i < fan; ++i) {
    const dvec3 c = glm::cross(emitter[i + 1] - emitter[0], emitter[i + 2] - emitter[0]);
    normal += c;
    area += 0.5 * glm::length(c);
    cumulative[i] = area;
  }
  if (!(area > 0.0)) return;
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
}

}  // namespace

EmitterSamples sample_emitter(const dvec3& r, const dvec3& n, std::span<const dvec3> emitter,
                              const SampledVisibilityOptions& options) {
  EmitterSamples out;
  std::vector<double> cumulative;
  sample_emitter_into(r, n, emitter, options, cumulative, out);
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
  Scratch& scratch = thread_scratch();
  std::vector<std::uint8_t>& blocked = scratch.blocked;
  blocked.assign(samples.points.size(), 0);
  // Rays towards points with zero weight change nothing: do not cast them.
  std::vector<dvec3>& targets = scratch.targets;
  std::vector<std::size_t>& index = scratch.index;
  targets.clear();
  index.clear();
  for (std::size_t i = 0; i < samples.points.size(); ++i)
    if (samples.weights[i] > 0.0) {
      targets.push_back(samples.points[i]);
      index.push_back(i);
    }
  std::vector<std::uint8_t>& hit = scratch.hit;
  hit.assign(targets.size(), 0);
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

namespace {

// The candidates of one link seen from one receiver point, laid out for
// segment tests from that point (Moller-Trumbore with the origin fixed): the
// parts that depend only on the point and the triangle are computed once, and
// the test of one segment against all candidates is a branch-free loop over
// arrays that the compiler vectorises.
struct CandidatesFromPoint {
  std::vector<double> e1x, e1y, e1z, e2x, e2y, e2z;  // triangle edges
  std::vector<double> sx, sy, sz;                    // r - v0
  std::vector<double> qx, qy, qz;                    // (r - v0) x e1
  std::vector<double> tq;                            // e2 . q: t times det

  // Lays out `candidates` as seen from r, reusing the arrays' storage.
  void reset(std::span<const Triangle> candidates, const dvec3& r) {
    for (auto* v : {&e1x, &e1y, &e1z, &e2x, &e2y, &e2z, &sx, &sy, &sz, &qx, &qy, &qz, &tq}) {
      v->clear();
      v->reserve(candidates.size());
    }
    for (const Triangle& t : candidates) {
      const dvec3 e1 = t.v[1] - t.v[0], e2 = t.v[2] - t.v[0], s = r - t.v[0];
      const dvec3 q = glm::cross(s, e1);
      e1x.push_back(e1.x), e1y.push_back(e1.y), e1z.push_back(e1.z);
      e2x.push_back(e2.x), e2y.push_back(e2.y), e2z.push_back(e2.z);
      sx.push_back(s.x), sy.push_back(s.y), sz.push_back(s.z);
      qx.push_back(q.x), qy.push_back(q.y), qz.push_back(q.z);
      tq.push_back(glm::dot(e2, q));
    }
  }

  // Is the open segment r -> r + d blocked? Same test as segment_hits_triangle,
  // with the divisions by det folded into the comparisons.
  bool blocked(const dvec3& d) const {
    const std::size_t n = tq.size();
    const double dx = d.x, dy = d.y, dz = d.z;
    const double* __restrict ax = e1x.data();
    const double* __restrict ay = e1y.data();
    const double* __restrict az = e1z.data();
    const double* __restrict bx = e2x.data();
    const double* __restrict by = e2y.data();
    const double* __restrict bz = e2z.data();
    const double* __restrict cx = sx.data();
    const double* __restrict cy = sy.data();
    const double* __restrict cz = sz.data();
    const double* __restrict wx = qx.data();
    const double* __restrict wy = qy.data();
    const double* __restrict wz = qz.data();
    const double* __restrict tt = tq.data();
    // Masks are kept as 0.0 / 1.0 doubles: with baseline x86-64 (SSE2) GCC
    // vectorises double selects, not mixed integer/double masks.
    double hit = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      const double px = dy * bz[i] - dz * by[i];
      const double py = dz * bx[i] - dx * bz[i];
      const double pz = dx * by[i] - dy * bx[i];
      const double det = ax[i] * px + ay[i] * py + az[i] * pz;
      const double sign = det < 0.0 ? -1.0 : 1.0;
      const double a = sign * det;  // |det|
      const double u = sign * (cx[i] * px + cy[i] * py + cz[i] * pz);
      const double v = sign * (dx * wx[i] + dy * wy[i] + dz * wz[i]);
      const double t = sign * tt[i];
      // Inside the triangle: u, v, det - u - v >= 0; strictly inside the open
      // segment: 1e-9 det < t < (1 - 1e-9) det (which also needs det > 0).
      const double barycentric = std::min(std::min(u, v), a - u - v);
      const double along = std::min(t - 1e-9 * a, (1.0 - 1e-9) * a - t);
      const double inside = std::min(barycentric >= 0.0 ? 1.0 : 0.0, along > 0.0 ? 1.0 : 0.0);
      hit += inside;
    }
    return hit != 0.0;
  }
};

}  // namespace

double visible_fraction(std::span<const Triangle> candidates, const dvec3& r,
                        const EmitterSamples& samples) {
  thread_local CandidatesFromPoint from;
  Scratch& scratch = thread_scratch();
  std::vector<std::uint8_t>& blocked = scratch.blocked;
  blocked.assign(samples.points.size(), 0);
  if (!candidates.empty()) {
    from.reset(candidates, r);
    for (std::size_t i = 0; i < samples.points.size(); ++i)
      if (samples.weights[i] > 0.0) blocked[i] = from.blocked(samples.points[i] - r);
  }
  return visible_fraction(samples, blocked);
}

FormFactorGradient sampled_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                const RayScene& scene,
                                                const SampledVisibilityOptions& options,
                                                std::uint32_t receiver_face,
                                                std::uint32_t emitter_face, double* open) {
  FormFactorGradient fg = form_factor_gradient(r, n, emitter);
  if (open) *open = fg.value;
  if (fg.value <= 0.0) return fg;
  Scratch& scratch = thread_scratch();
  sample_emitter_into(r, n, emitter, options, scratch.cumulative, scratch.samples);
  const double fraction = visible_fraction(scene, r, scratch.samples, receiver_face, emitter_face);
  return {fraction * fg.value, fraction * fg.gradient};
}

FormFactorGradient sampled_form_factor_gradient(const dvec3& r, const dvec3& n,
                                                std::span<const dvec3> emitter,
                                                std::span<const Triangle> candidates,
                                                const SampledVisibilityOptions& options,
                                                double* open) {
  FormFactorGradient fg = form_factor_gradient(r, n, emitter);
  if (open) *open = fg.value;
  if (fg.value <= 0.0 || candidates.empty()) return fg;
  Scratch& scratch = thread_scratch();
  sample_emitter_into(r, n, emitter, options, scratch.cumulative, scratch.samples);
  const double fraction = visible_fraction(candidates, r, scratch.samples);
  return {fraction * fg.value, fraction * fg.gradient};
}

}  // namespace radiosity
