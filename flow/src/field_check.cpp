#include "field_check.hpp"

#include <stdexcept>

#include "neuflow/flow/limits.hpp"

namespace neuflow::flow::detail {

void check_field(const FlowField& field, const std::string& context) {
  if (!flow_size_acceptable(field.width, field.height)) {
    throw std::invalid_argument(context + ": flow field size " + std::to_string(field.width) + "x" +
                                std::to_string(field.height) + " is empty or beyond the supported limits");
  }
  if (field.uv.size() != 2 * field.pixel_count()) {
    throw std::invalid_argument(context + ": flow field has " + std::to_string(field.uv.size()) +
                                " uv values, expected 2 x " + std::to_string(field.width) + " x " +
                                std::to_string(field.height));
  }
  if (!field.valid.empty() && field.valid.size() != field.pixel_count()) {
    throw std::invalid_argument(context + ": flow field mask has " + std::to_string(field.valid.size()) +
                                " entries, expected " + std::to_string(field.pixel_count()));
  }
}

}  // namespace neuflow::flow::detail
