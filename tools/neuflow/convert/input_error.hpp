#pragma once
// Why one input of `neuflow convert` failed. The other inputs still get converted; the
// command's exit code is that of the first failed input.
#include <stdexcept>
#include <string>

namespace neuflow::pipeline {
class PipelineError;
}

namespace neuflow::cli {

struct InputError : std::runtime_error {
  // `message` names the file at fault (the input, or a frame inside a folder).
  InputError(int code, const std::string& message) : std::runtime_error(message), exit_code(code) {}
  int exit_code;  // one of the kExit* codes of common/exit_codes.hpp
};

// The same message, with the exit code for its kind: missing → 66, undecodable → 65,
// unwritable → 73, anything else → 1.
InputError to_input_error(const pipeline::PipelineError& e);

}  // namespace neuflow::cli
