// One function per concept adds its bindings to the test-only module.
#pragma once

#include <pybind11/pybind11.h>

namespace radiosity::python {

void bind_form_factors(pybind11::module_& m);
void bind_visibility(pybind11::module_& m);

}  // namespace radiosity::python
