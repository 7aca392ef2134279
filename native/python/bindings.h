// One function per concept adds its Python bindings to the module.
#pragma once

#include <pybind11/pybind11.h>

namespace radiosity::python {

void bind_solver(pybind11::module_& m);

}  // namespace radiosity::python
