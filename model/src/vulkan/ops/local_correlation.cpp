#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LocalCorrelation& op) { record_op(r, op, nullptr); }

// With `previous`, that step's update (refine_update.cpp's op) in the same dispatch: the hidden
// state, the flow's copy and the correlation share the step input's buffer.
void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::RefineUpdate* previous) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  LocalCorrelationParams p{out.h, out.w, f0.c, f0.offset(), f1.offset(), flow.offset(), out.offset(), 0, 0, 0};
  const Work work{r.bytes(f0.count() + f1.count() + flow.count()), r.bytes(out.count()),
                  static_cast<long long>(out.count()) * f0.c};
  const auto grid = groups(static_cast<long>(out.h) * out.w, 16);
  if (!previous) {
    r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, out.buffer, flow.buffer}, p, work, grid);
    return;
  }
  const View update = r.view(previous->update), hidden = r.view(previous->hidden),
             flow_copy = r.view(previous->flow_copy);
  if (hidden.buffer != out.buffer || flow_copy.buffer != out.buffer || previous->flow.tensor != op.flow.tensor) {
    throw std::logic_error(
        "the Vulkan refinement step fuses its update only into a correlation of the same step input");
  }
  p.update_off = update.offset();
  p.hidden_off = hidden.offset();
  p.flow_copy_off = flow_copy.offset();
  r.dispatch<Shader::local_correlation_update>(
      {f0.buffer, f1.buffer, out.buffer, flow.buffer, update.buffer}, p,
      {work.read + r.bytes(update.count()), work.written + r.bytes(hidden.count() + flow_copy.count() + flow.count()),
       work.multiply_adds},
      grid);
}

}  // namespace neuflow::model::vulkan
