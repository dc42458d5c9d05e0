#pragma once
// The parts of the `neuflow` Python module (module.cpp puts them together).
#include <pybind11/pybind11.h>

namespace neuflow::python {

// neuflow.Model, neuflow.Session (model_binding.cpp).
void bind_model(pybind11::module_& m);
// read_flow, write_flow, flow_to_color, epe, metrics (flow_binding.cpp).
void bind_flow(pybind11::module_& m);
// ModelError, BackendError and how the core's exceptions become Python's (errors.cpp).
void bind_errors(pybind11::module_& m);

}  // namespace neuflow::python
