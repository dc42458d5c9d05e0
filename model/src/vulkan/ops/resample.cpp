#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::Resample& op) {
  const View in = r.view(op.in), out = r.view(op.out);
  const ResampleParams p{in.c, in.h, in.w, in.offset(), out.offset(), op.factor, op.relu ? 1 : 0, op.scale};
  r.dispatch<Shader::resample>({in.buffer, nullptr, out.buffer, nullptr}, p,
                               {r.bytes(in.count()), r.bytes(out.count()), 0}, groups(out.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
