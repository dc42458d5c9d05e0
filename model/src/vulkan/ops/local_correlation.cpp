#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LocalCorrelation& op) { record_op(r, op, nullptr); }

namespace {

// The correlation in local_correlation_update.comp's form, which also writes the step input's
// hidden state and flow channels (`hidden`, `flow_copy`, in the output's buffer): from the
// previous step's update (`update`) or, without one, zeros and the flow as it is.
void record_with_step_input(Recorder& r, const graph::LocalCorrelation& op, const graph::Slice* update,
                            const graph::Slice& hidden_slice, const graph::Slice& flow_copy_slice) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  const View hidden = r.view(hidden_slice), flow_copy = r.view(flow_copy_slice);
  if (hidden.buffer != out.buffer || flow_copy.buffer != out.buffer || hidden.c != 64 || flow_copy.c != 2) {
    throw std::logic_error(
        "the Vulkan refinement step fuses its input's first values or its update only into a "
        "correlation of the same step input");
  }
  const View upd = update ? r.view(*update) : View{};
  const LocalCorrelationParams p{out.h,
                                 out.w,
                                 f0.c,
                                 f0.offset(),
                                 f1.offset(),
                                 flow.offset(),
                                 out.offset(),
                                 update ? upd.offset() : -1,
                                 hidden.offset(),
                                 flow_copy.offset()};
  // Without an update the flow is read, not written back.
  const long long read = f0.count() + f1.count() + flow.count() + (update ? upd.count() : 0);
  const long long written = out.count() + hidden.count() + flow_copy.count() + (update ? flow.count() : 0);
  r.dispatch<Shader::local_correlation_update>(
      {f0.buffer, f1.buffer, out.buffer, flow.buffer, upd.buffer}, p,
      {r.bytes(read), r.bytes(written), static_cast<long long>(out.count()) * f0.c},
      groups(static_cast<long>(out.h) * out.w, 16));
}

}  // namespace

// With `previous`, that step's update (refine_update.cpp's op) in the same dispatch: the hidden
// state, the flow's copy and the correlation share the step input's buffer.
void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::RefineUpdate* previous) {
  if (previous) {
    if (previous->flow.tensor != op.flow.tensor) {
      throw std::logic_error("the Vulkan refinement step fuses its update only into a correlation of its own flow");
    }
    record_with_step_input(r, op, &previous->update, previous->hidden, previous->flow_copy);
    return;
  }
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  const LocalCorrelationParams p{out.h, out.w, f0.c, f0.offset(), f1.offset(), flow.offset(), out.offset(), 0, 0, 0};
  r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, out.buffer, flow.buffer}, p,
                                        {r.bytes(f0.count() + f1.count() + flow.count()), r.bytes(out.count()),
                                         static_cast<long long>(out.count()) * f0.c},
                                        groups(static_cast<long>(out.h) * out.w, 16));
}

void record_op(Recorder& r, const graph::LocalCorrelation& op, const graph::Zero& hidden,
               const graph::Copy& flow_copy) {
  if (flow_copy.in.tensor != op.flow.tensor) {
    throw std::logic_error("the Vulkan refinement step starts its input only with its own flow");
  }
  record_with_step_input(r, op, nullptr, hidden.out, flow_copy.out);
}

}  // namespace neuflow::model::vulkan
