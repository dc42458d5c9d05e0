// The `neuflow` Python module's compiled part, neuflow._neuflow (python/neuflow/__init__.py
// re-exports it with the type stubs beside it).
#include <pybind11/pybind11.h>

#include "bindings.hpp"

PYBIND11_MODULE(_neuflow, m) {
  m.doc() = "NeuFlow-V2 optical flow: the core, the flow formats and the pictures from NumPy.";
  m.attr("__version__") = NEUFLOW_VERSION;
  // pybind11 before 2.12 reads NumPy 1's dtype layout only; __init__.py refuses NumPy 2 then.
  m.attr("_pybind11_version") = pybind11::make_tuple(PYBIND11_VERSION_MAJOR, PYBIND11_VERSION_MINOR);
  neuflow::python::bind_errors(m);
  neuflow::python::bind_model(m);
  neuflow::python::bind_flow(m);
}
