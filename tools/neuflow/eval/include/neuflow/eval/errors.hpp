#pragma once
// The one exception type of the evaluation library (besides the flow readers' FlowFileError
// and the model's CheckpointError, which pass through). Messages name the file or folder and
// what was expected there; kind() lets the command map failures to exit codes.
#include <stdexcept>
#include <string>

namespace neuflow::eval {

class EvalError : public std::runtime_error {
 public:
  enum class Kind {
    missing_input,    // a dataset folder, image, ground truth or prediction is absent
    malformed_input,  // present but unusable: undecodable image, sizes that disagree, bad split file
  };

  EvalError(Kind kind, const std::string& message);
  Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

}  // namespace neuflow::eval
