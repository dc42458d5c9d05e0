#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::ChannelAffine<DeviceTensor>& op) {
  const View x = r.view(op.inout);
  const ChannelAffineParams p{x.c, x.h * x.w, x.offset(), op.scale->offset, op.shift->offset};
  r.dispatch<Shader::channel_affine>({&r.weights(), nullptr, x.buffer, nullptr}, p,
                                     {r.bytes(x.count() + 2LL * x.c), r.bytes(x.count()), 0},
                                     groups(x.count(), kLocal));
}

}  // namespace neuflow::model::vulkan
