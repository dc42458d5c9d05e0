#include "neuflow/eval/errors.hpp"

namespace neuflow::eval {

EvalError::EvalError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}

}  // namespace neuflow::eval
