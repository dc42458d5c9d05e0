#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LayerNorm<DeviceTensor>& op, const graph::ChannelAffine<DeviceTensor>* then) {
  const View in = r.view(op.in), out = r.view(op.out);
  const View residual = op.residual ? r.view(*op.residual) : View{};
  const int tokens = in.h * in.w;
  const LayerNormParams p{in.c,
                          tokens,
                          in.offset(),
                          out.offset(),
                          op.residual ? residual.offset() : -1,
                          op.weights->gamma.offset,
                          op.weights->beta.offset,
                          then ? then->scale->offset : -1,
                          then ? then->shift->offset : -1};
  const long long read = in.count() + (then ? 4LL : 2LL) * in.c + (op.residual ? out.count() : 0);
  r.dispatch<Shader::layer_norm>({&r.weights(), in.buffer, out.buffer, residual.buffer}, p,
                                 {r.bytes(read), r.bytes(out.count()), 0}, groups(tokens, 16));
}

}  // namespace neuflow::model::vulkan
