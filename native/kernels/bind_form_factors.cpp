// Python access to the form-factor kernels, so they can be checked and used
// from scripts: form_factor() and form_factor_gradient().
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <vector>

#include "core/geometry/form_factor.h"
#include "kernels/bindings.h"
#include "python/numpy_input.h"

namespace py = pybind11;

namespace radiosity::python {
namespace {

struct KernelInput {
  dvec3 point;
  dvec3 normal;
  std::vector<dvec3> polygon;
};

KernelInput read_kernel_input(const py::handle& point, const py::handle& normal,
                              const py::handle& polygon) {
  KernelInput in;
  in.point = read_point(point, "point");
  in.normal = read_unit_vec3(normal, "normal");
  in.polygon = read_polygon(polygon, "polygon");
  return in;
}

}  // namespace

void bind_form_factors(py::module_& m) {
  m.def(
      "form_factor",
      [](const py::handle& point, const py::handle& normal, const py::handle& polygon) {
        const KernelInput in = read_kernel_input(point, normal, polygon);
        return form_factor(in.point, in.normal, in.polygon);
      },
      py::arg("point"), py::arg("normal"), py::arg("polygon"),
      "Form factor from a receiver point with the given normal to a planar polygon\n"
      "((n, 3) array, counter-clockwise about its front normal). Clipped to the\n"
      "receiver's upper half-space; 0 when the point is behind or on the polygon's plane.");
  m.def(
      "form_factor_gradient",
      [](const py::handle& point, const py::handle& normal, const py::handle& polygon) {
        const KernelInput in = read_kernel_input(point, normal, polygon);
        const FormFactorGradient result = form_factor_gradient(in.point, in.normal, in.polygon);
        return py::make_tuple(result.value, to_numpy(result.gradient));
      },
      py::arg("point"), py::arg("normal"), py::arg("polygon"),
      "(F, grad F): the form factor and its exact gradient with respect to the point.");
}

}  // namespace radiosity::python
