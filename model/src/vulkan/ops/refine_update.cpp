#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// refine_update.comp writes the hidden state and the flow's copy into one buffer (the step's
// input) and reads conv3's output from the start of its own.
void record_op(Recorder& r, const graph::RefineUpdate& op) {
  const View update = r.view(op.update), hidden = r.view(op.hidden), flow_copy = r.view(op.flow_copy),
             flow = r.view(op.flow);
  require_whole(update, "refinement update");
  if (hidden.buffer != flow_copy.buffer) {
    throw std::logic_error("the Vulkan refinement update needs the hidden state and the flow's copy in one tensor");
  }
  const RefineUpdateParams p{flow.h * flow.w, hidden.offset(), flow_copy.offset(), flow.offset()};
  r.dispatch<Shader::refine_update>(
      {update.buffer, nullptr, hidden.buffer, flow.buffer}, p,
      {r.bytes(update.count() + flow.count()), r.bytes(hidden.count() + flow_copy.count() + flow.count()), 0},
      groups(static_cast<long>(flow.h) * flow.w, kLocal));
}

}  // namespace neuflow::model::vulkan
