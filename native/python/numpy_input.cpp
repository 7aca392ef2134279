#include "python/numpy_input.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

#include "core/geometry/polygon.h"
#include "radiosity/scene.h"

namespace py = pybind11;

namespace radiosity::python {
namespace {

std::string shape_string(const py::array& a) {
  std::ostringstream out;
  out << "(";
  for (py::ssize_t i = 0; i < a.ndim(); ++i) out << (i ? ", " : "") << a.shape(i);
  out << (a.ndim() == 1 ? ",)" : ")");
  return out.str();
}

std::string expected_string(const std::vector<py::ssize_t>& shape) {
  std::ostringstream out;
  out << "(";
  for (size_t i = 0; i < shape.size(); ++i) {
    out << (i ? ", " : "");
    if (shape[i] < 0)
      out << (i == 0 ? "n" : "k");
    else
      out << shape[i];
  }
  out << (shape.size() == 1 ? ",)" : ")");
  return out.str();
}

}  // namespace

void require_shape(const py::array& a, const std::string& name,
                   const std::vector<py::ssize_t>& shape) {
  bool ok = a.ndim() == static_cast<py::ssize_t>(shape.size());
  for (size_t i = 0; ok && i < shape.size(); ++i) {
    ok = shape[i] < 0 || a.shape(static_cast<py::ssize_t>(i)) == shape[i];
  }
  if (!ok) {
    throw std::invalid_argument(name + " must have shape " + expected_string(shape) + ", got " +
                                shape_string(a));
  }
}

InputArray<double> read_array(const py::handle& object, const std::string& name,
                              const std::vector<py::ssize_t>& shape) {
  auto a = read_array_of<double>(object, name, shape);
  require_finite(a.data(), static_cast<size_t>(a.size()), name);
  return a;
}

void require_finite(const double* data, size_t count, const std::string& name) {
  for (size_t i = 0; i < count; ++i) {
    if (!std::isfinite(data[i])) {
      throw std::invalid_argument(name +
                                  " contains a non-finite value (NaN or infinity) at flat index " +
                                  std::to_string(i));
    }
  }
}

dvec3 read_vec3(const py::handle& object, const std::string& name) {
  const auto a = read_array(object, name, {3});
  return {a.at(0), a.at(1), a.at(2)};
}

void require_coordinates(const double* data, size_t count, const std::string& name) {
  for (size_t i = 0; i < count; ++i) {
    if (!(std::abs(data[i]) <= kMaxCoordinate)) {
      std::ostringstream message;
      message << name << " has a coordinate of magnitude " << std::abs(data[i]) << " at flat index "
              << i << ", beyond the " << kMaxCoordinate << " a scene may have";
      throw std::invalid_argument(message.str());
    }
  }
}

dvec3 read_point(const py::handle& object, const std::string& name) {
  const auto a = read_array(object, name, {3});
  require_coordinates(a.data(), 3, name);
  return {a.at(0), a.at(1), a.at(2)};
}

dvec3 read_unit_vec3(const py::handle& object, const std::string& name) {
  const dvec3 v = read_vec3(object, name);
  const double length = glm::length(v);
  if (!(length > 0.0) || !std::isfinite(length)) {
    throw std::invalid_argument(name + " must be a non-zero vector");
  }
  return v / length;
}

std::vector<dvec3> read_polygon(const py::handle& object, const std::string& name) {
  const auto a = read_array(object, name, {-1, 3});
  const size_t n = static_cast<size_t>(a.shape(0));
  if (n < 3) {
    throw std::invalid_argument(name + " needs at least 3 vertices, got " + std::to_string(n));
  }
  require_coordinates(a.data(), 3 * n, name);
  std::vector<dvec3> polygon(n);
  const double* p = a.data();
  for (size_t i = 0; i < n; ++i) polygon[i] = {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
  // Zero-area and collinear polygons are rejected here, with the reason, so the
  // kernels never see them (MATH.md s3).
  if (!encloses_area(polygon)) {
    throw std::invalid_argument(name + " has zero area (collinear or coincident vertices)");
  }
  return polygon;
}

py::array_t<double> to_numpy(const dvec3& v) {
  py::array_t<double> out(3);
  auto w = out.mutable_unchecked<1>();
  w(0) = v.x;
  w(1) = v.y;
  w(2) = v.z;
  return out;
}

}  // namespace radiosity::python
