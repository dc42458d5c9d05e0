#pragma once
// Consistency of a FlowField handed to a writer or an algorithm (internal).
#include <string>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow::detail {

// Throws std::invalid_argument, prefixed with `context`, when the field's size is outside
// the accepted limits or uv / valid do not match width × height.
void check_field(const FlowField& field, const std::string& context);

}  // namespace neuflow::flow::detail
