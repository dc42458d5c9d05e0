// The `neuflow` Python module's compiled part, neuflow._neuflow (python/neuflow/__init__.py
// re-exports it with the type stubs beside it).
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_neuflow, m) {
  m.doc() = "NeuFlow-V2 optical flow: the core, the flow formats and the pictures from NumPy.";
  m.attr("__version__") = NEUFLOW_VERSION;
  neuflow::python::bind_errors(m);
  neuflow::python::bind_model(m);
  neuflow::python::bind_flow(m);
}
