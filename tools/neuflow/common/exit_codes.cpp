#include "common/exit_codes.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace neuflow::cli {

int exit_code_for(const flow::FlowFileError& e) {
  switch (e.kind()) {
    case flow::FlowFileError::Kind::not_found: return kExitNoInput;
    case flow::FlowFileError::Kind::write_failed: return kExitCantCreate;
    case flow::FlowFileError::Kind::malformed:
    case flow::FlowFileError::Kind::unsupported_format: return kExitDataError;
  }
  return kExitFailure;
}

int exit_code_for(const model::CheckpointError& e) {
  return e.kind() == model::CheckpointError::Kind::kIo ? kExitNoInput : kExitDataError;
}

}  // namespace neuflow::cli
