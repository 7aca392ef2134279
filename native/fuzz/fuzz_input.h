// What the libFuzzer harnesses share (`make fuzz`, tools/fuzz.py): a reader of
// the input bytes, the checks the Python bindings make before calling a kernel
// (so the harnesses call the kernels only as the module can), and the output
// checks. The input layout is sequential little-endian fields, read past the
// end as zeros, so the seed corpus (native/fuzz/make_corpus.py) writes cases
// field by field and every mutation still parses.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <vector>

#include "core/geometry/form_factor.h"
#include "core/geometry/polygon.h"
#include "core/visibility/visible_polygon.h"
#include "radiosity/scene.h"
#include "radiosity/vec.h"

namespace radiosity::fuzz {

class Reader {
 public:
  Reader(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}

  template <class T>
  T take() {
    T value{};
    unsigned char bytes[sizeof(T)] = {};
    const std::size_t n = pos_ < size_ ? std::min(sizeof(T), size_ - pos_) : 0;
    if (n) std::memcpy(bytes, data_ + pos_, n);
    pos_ += sizeof(T);
    std::memcpy(&value, bytes, sizeof(T));
    return value;
  }
  std::uint8_t u8() { return take<std::uint8_t>(); }
  std::uint16_t u16() { return take<std::uint16_t>(); }
  std::int64_t i64() { return take<std::int64_t>(); }
  double f64() { return take<double>(); }
  dvec3 vec3() {
    const double x = f64(), y = f64();
    return {x, y, f64()};
  }
  // A count in [0, limit].
  std::size_t count(std::size_t limit) { return u16() % (limit + 1); }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t pos_ = 0;
};

// A finding: printed, then abort() so libFuzzer saves the input.
[[noreturn]] inline void fail(const char* what, double value = 0.0) {
  std::fprintf(stderr, "FUZZ FINDING: %s (%.17g)\n", what, value);
  std::abort();
}

inline void require_finite(double v, const char* what) {
  if (!std::isfinite(v)) fail(what, v);
}
inline void require_finite(const dvec3& v, const char* what) {
  for (int k = 0; k < 3; ++k) require_finite(v[k], what);
}

inline bool finite(const dvec3& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

// python/numpy_input.cpp, require_coordinates: finite and within
// kMaxCoordinate, as a point, polygon or occluder of the kernels must be.
inline bool in_range(const dvec3& v) {
  return std::abs(v.x) <= kMaxCoordinate && std::abs(v.y) <= kMaxCoordinate &&
         std::abs(v.z) <= kMaxCoordinate;
}

// python/numpy_input.cpp, read_polygon: at least 3 vertices within range, not of zero area.
inline bool valid_polygon(std::span<const dvec3> polygon) {
  const std::size_t n = polygon.size();
  if (n < 3) return false;
  for (const dvec3& v : polygon)
    if (!in_range(v)) return false;
  return encloses_area(polygon);
}

// kernels/bind_visibility.cpp, require_planar_convex.
inline bool planar_convex(std::span<const dvec3> polygon) {
  return planar_convex_problem(polygon) == nullptr;
}

// python/numpy_input.cpp, read_unit_vec3: finite, non-zero, normalised.
inline bool unit_normal(const dvec3& v, dvec3& out) {
  if (!finite(v)) return false;
  const double length = glm::length(v);
  if (!(length > 0.0) || !std::isfinite(length)) return false;
  out = v / length;
  return true;
}

// A polygon from the input: either raw vertices, or (when `shaped`) a convex
// polygon made from a centre, a normal, a radius and n angles, so mutations
// reach the kernels past the validity checks more often.
inline std::vector<dvec3> read_polygon(Reader& in, std::size_t max_vertices) {
  const std::uint8_t mode = in.u8();
  const std::size_t n = 3 + in.count(max_vertices - 3);
  std::vector<dvec3> polygon(n);
  if (mode % 2 == 0) {
    for (dvec3& v : polygon) v = in.vec3();
    return polygon;
  }
  const dvec3 centre = in.vec3();
  dvec3 normal;
  if (!unit_normal(in.vec3(), normal)) normal = dvec3(0, 0, 1);
  const double radius = in.f64();
  const dvec3 helper = std::abs(normal.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  const dvec3 t1 = glm::normalize(glm::cross(helper, normal)), t2 = glm::cross(normal, t1);
  for (std::size_t i = 0; i < n; ++i) {
    // Angles in increasing order: counter-clockwise about the normal.
    const double angle =
        2.0 * kPi * (static_cast<double>(i) + (in.u8() / 256.0)) / static_cast<double>(n);
    polygon[i] = centre + radius * (std::cos(angle) * t1 + std::sin(angle) * t2);
  }
  return polygon;
}

}  // namespace radiosity::fuzz
