#include "convert/input_error.hpp"

#include "common/exit_codes.hpp"
#include "neuflow/pipeline/pipeline_error.hpp"

namespace neuflow::cli {

InputError to_input_error(const pipeline::PipelineError& e) {
  using Kind = pipeline::PipelineError::Kind;
  switch (e.kind()) {
    case Kind::not_found: return InputError(kExitNoInput, e.what());
    case Kind::undecodable: return InputError(kExitDataError, e.what());
    case Kind::write_failed: return InputError(kExitCantCreate, e.what());
    case Kind::missing_element:
    case Kind::invalid_argument:
    case Kind::failed: break;
  }
  return InputError(kExitFailure, e.what());
}

}  // namespace neuflow::cli
