// Validated conversion of numpy input: every array that crosses into the core
// is checked for shape and finiteness here, with a message naming the argument.
// Errors are std::invalid_argument, which pybind11 raises as ValueError.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "core/vec.h"

namespace radiosity::python {

// A float64 C-contiguous array of the given rank whose trailing dimensions match
// `trailing` (-1 = any); the leading one is free. Converts lists and other dtypes.
pybind11::array_t<double, pybind11::array::c_style | pybind11::array::forcecast> read_array(
    const pybind11::handle& object, const std::string& name, std::vector<pybind11::ssize_t> shape);

// Throws if any value of the array is NaN or infinite.
void require_finite(const double* data, size_t count, const std::string& name);

dvec3 read_vec3(const pybind11::handle& object, const std::string& name);
dvec3 read_unit_vec3(const pybind11::handle& object, const std::string& name);

// A planar polygon (n, 3), n >= 3, finite, with non-zero area.
std::vector<dvec3> read_polygon(const pybind11::handle& object, const std::string& name);

pybind11::array_t<double> to_numpy(const dvec3& v);

}  // namespace radiosity::python
