// The private Python module `_radiosity`: one entry point that gathers the
// bindings of each concept (bind_*.cpp). C++ exceptions become Python ones
// (std::invalid_argument -> ValueError, std::bad_alloc -> MemoryError), so a
// bad call never brings down the host process (Blender).
#include <pybind11/pybind11.h>

#include "python/bindings.h"

namespace py = pybind11;

PYBIND11_MODULE(_radiosity, m) {
  m.doc() = "Native hierarchical radiosity solver for the Radiosity add-on";
  m.attr("__version__") = RADIOSITY_VERSION;
  radiosity::python::bind_solver(m);
}
