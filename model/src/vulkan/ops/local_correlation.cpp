#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LocalCorrelation& op) {
  const View f0 = r.view(op.f0), f1 = r.view(op.f1), flow = r.view(op.flow), out = r.view(op.out);
  const LocalCorrelationParams p{out.h, out.w, f0.c, f0.offset(), f1.offset(), flow.offset(), out.offset()};
  r.dispatch<Shader::local_correlation>({f0.buffer, f1.buffer, out.buffer, flow.buffer}, p,
                                        {r.bytes(f0.count() + f1.count() + flow.count()), r.bytes(out.count()),
                                         static_cast<long long>(out.count()) * f0.c},
                                        groups(static_cast<long>(out.h) * out.w, 16));
}

}  // namespace neuflow::model::vulkan
