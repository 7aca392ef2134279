// The test-only Python module `_radiosity_kernels`: the solver's kernels
// (form factors, their gradients, visible polygons and occluded form factors)
// for tests, fuzzers and figures to check one by one. Built beside the add-on
// and never shipped in it: the add-on calls only what `_radiosity` holds.
#include <pybind11/pybind11.h>

#include "kernels/bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(_radiosity_kernels, m) {
  m.doc() = "The radiosity solver's kernels, for tests (never shipped in the add-on)";
  radiosity::python::bind_form_factors(m);
  radiosity::python::bind_visibility(m);
}
