#include "neuflow/pipeline/pipeline_error.hpp"

#include <utility>

namespace neuflow::pipeline {

PipelineError::PipelineError(Kind kind, std::string subject, const std::string& problem)
    : std::runtime_error(subject + ": " + problem), kind_(kind), subject_(std::move(subject)), problem_(problem) {}

}  // namespace neuflow::pipeline
