// Validated conversion of numpy input: every array that crosses into the core
// is checked for shape and finiteness here, with a message naming the argument.
// Errors are std::invalid_argument, which pybind11 raises as ValueError.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "radiosity/vec.h"

namespace radiosity::python {

template <class T>
using InputArray = pybind11::array_t<T, pybind11::array::c_style | pybind11::array::forcecast>;

// Throws unless `a` has `shape` (-1: any size on that axis).
void require_shape(const pybind11::array& a, const std::string& name,
                   const std::vector<pybind11::ssize_t>& shape);

// A C-contiguous array of T with the given shape (-1: any size on that axis),
// converted from lists and other dtypes.
template <class T>
InputArray<T> read_array_of(const pybind11::handle& object, const std::string& name,
                            const std::vector<pybind11::ssize_t>& shape) {
  if (object.is_none()) throw std::invalid_argument(name + " must be an array, got None");
  InputArray<T> a;
  try {
    a = InputArray<T>::ensure(object);
  } catch (const pybind11::error_already_set&) {
    a = {};
  }
  if (!a) throw std::invalid_argument(name + " must be convertible to a numeric array");
  require_shape(a, name, shape);
  return a;
}

// The same for float64, with every value finite.
InputArray<double> read_array(const pybind11::handle& object, const std::string& name,
                              const std::vector<pybind11::ssize_t>& shape);

// Throws if any value of the array is NaN or infinite.
void require_finite(const double* data, size_t count, const std::string& name);

// Throws if any value's magnitude exceeds kMaxCoordinate (include/radiosity/scene.h): the
// kernels take points, polygons and occluders in the range a scene may have
// (their products of four lengths overflow near 1e77, and beyond 1e154 the
// visible-polygon code made NaN; libFuzzer visible_polygon, crash-516ec420).
void require_coordinates(const double* data, size_t count, const std::string& name);

dvec3 read_vec3(const pybind11::handle& object, const std::string& name);
// A point of the kernels: finite and within kMaxCoordinate.
dvec3 read_point(const pybind11::handle& object, const std::string& name);
dvec3 read_unit_vec3(const pybind11::handle& object, const std::string& name);

// A polygon (n, 3), n >= 3, finite, within kMaxCoordinate, with non-zero area.
std::vector<dvec3> read_polygon(const pybind11::handle& object, const std::string& name);

pybind11::array_t<double> to_numpy(const dvec3& v);

}  // namespace radiosity::python
