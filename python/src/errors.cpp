// The core's exceptions as Python's: a checkpoint that is not NeuFlow-V2 raises
// neuflow.ModelError, a GPU that cannot run neuflow.BackendError (a RuntimeError), files that
// cannot be read or written OSError (FileNotFoundError when missing), unusable arguments
// ValueError (pybind11 maps std::invalid_argument so). The messages are the core's.
#include <pybind11/pybind11.h>

#include <filesystem>
#include <system_error>

#include "bindings.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::python {

namespace py = pybind11;

void bind_errors(py::module_& m) {
  // Kept for the translator, which runs after init, and never destroyed: a static's destructor
  // would release a Python object after the interpreter has finished.
  static auto& model_error = *new py::exception<model::CheckpointError>(m, "ModelError", PyExc_Exception);
  static auto& backend_error = *new py::exception<model::BackendError>(m, "BackendError", PyExc_RuntimeError);
  model_error.doc() = "The file is not a NeuFlow-V2 checkpoint the core can load (the message says why).";
  backend_error.doc() = "The Vulkan backend cannot run: no device, out of memory, a lost device.";
  // By value: pybind11's translators are void(*)(std::exception_ptr).
  py::register_exception_translator([](std::exception_ptr p) {  // NOLINT(performance-unnecessary-value-param)
    try {
      if (p) std::rethrow_exception(p);
    } catch (const model::CheckpointError& e) {
      if (e.kind() == model::CheckpointError::Kind::kIo) {
        PyErr_SetString(PyExc_OSError, e.what());  // Model() says FileNotFoundError where the file is missing
      } else {
        model_error(e.what());
      }
    } catch (const model::BackendError& e) {
      backend_error(e.what());
    } catch (const flow::FlowFileError& e) {
      std::error_code ec;
      switch (e.kind()) {
        case flow::FlowFileError::Kind::not_found:  // also unreadable ones, and folders: those are OSError
          PyErr_SetString(std::filesystem::exists(e.path(), ec) ? PyExc_OSError : PyExc_FileNotFoundError, e.what());
          break;
        case flow::FlowFileError::Kind::unsupported_format: PyErr_SetString(PyExc_ValueError, e.what()); break;
        default: PyErr_SetString(PyExc_OSError, e.what()); break;
      }
    }
  });
}

}  // namespace neuflow::python
