#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

View resampled_flow(Recorder& r, const graph::RefineUpdate& op, const graph::Resample* then) {
  if (!then) return {};
  const View flow = r.view(op.flow), resampled = r.view(then->out);
  if (then->in.tensor != op.flow.tensor || then->in.channel != op.flow.channel || then->in.c != 2 || then->relu ||
      resampled.h != flow.h * then->factor || resampled.w != flow.w * then->factor) {
    throw std::logic_error("the Vulkan refinement update resamples only its whole new flow");
  }
  return resampled;
}

// refine_update.comp writes the hidden state and the flow's copy into one buffer (the step's
// input) and reads conv3's output from the start of its own.
void record_op(Recorder& r, const graph::RefineUpdate& op, const graph::Resample* then) {
  const View update = r.view(op.update), hidden = r.view(op.hidden), flow_copy = r.view(op.flow_copy),
             flow = r.view(op.flow);
  require_whole(update, "refinement update");
  if (hidden.buffer != flow_copy.buffer) {
    throw std::logic_error("the Vulkan refinement update needs the hidden state and the flow's copy in one tensor");
  }
  const View resampled = resampled_flow(r, op, then);
  const RefineUpdateParams p{flow.h * flow.w,         flow.w,
                             hidden.offset(),         flow_copy.offset(),
                             flow.offset(),           then ? resampled.offset() : -1,
                             then ? then->factor : 1, then ? then->scale : 1.f};
  r.dispatch<Shader::refine_update>(
      {update.buffer, then ? resampled.buffer : nullptr, hidden.buffer, flow.buffer}, p,
      {r.bytes(update.count() + flow.count()),
       r.bytes(hidden.count() + flow_copy.count() + flow.count() + (then ? resampled.count() : 0)), 0},
      groups(static_cast<long>(flow.h) * flow.w, kLocal));
}

}  // namespace neuflow::model::vulkan
