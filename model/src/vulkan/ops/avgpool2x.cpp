#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::AvgPool2x& op) {
  const View in = r.view(op.in), out = r.view(op.out);
  require_whole(in, "average pooling");
  require_whole(out, "average pooling");
  r.dispatch<Shader::avgpool2x>({in.buffer, nullptr, out.buffer, nullptr}, Avgpool2xParams{in.c, in.h, in.w},
                                {r.bytes(in.count()), r.bytes(out.count()), 0}, groups(out.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
