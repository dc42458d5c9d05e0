#include "neuflow/flow/errors.hpp"

#include <utility>

namespace neuflow::flow {

FlowFileError::FlowFileError(Kind kind, std::filesystem::path path, const std::string& problem)
    : std::runtime_error(path.string() + ": " + problem), kind_(kind), path_(std::move(path)), problem_(problem) {}

}  // namespace neuflow::flow
