#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

void record_op(Recorder& r, const graph::LayerNorm<DeviceTensor>& op, const graph::ChannelAffine<DeviceTensor>* then,
               const UnstackedOutput* unstacked) {
  const View in = r.view(op.in);
  const View out = r.view(unstacked ? unstacked->frames[0] : op.out);
  const View out2 = unstacked ? r.view(unstacked->frames[1]) : View{};
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
                          then ? then->shift->offset : -1,
                          unstacked ? tokens / 2 : 0,
                          unstacked ? out2.offset() : 0};
  const long long written = static_cast<long long>(in.c) * tokens;
  const long long read = in.count() + (then ? 4LL : 2LL) * in.c + (op.residual ? written : 0);
  const Work work{r.bytes(read), r.bytes(written), 0};
  if (unstacked) {
    r.dispatch<Shader::layer_norm_unstacked>({&r.weights(), in.buffer, out.buffer, residual.buffer, out2.buffer}, p,
                                             work, groups(tokens, 16));
  } else {
    r.dispatch<Shader::layer_norm>({&r.weights(), in.buffer, out.buffer, residual.buffer}, p, work, groups(tokens, 16));
  }
}

}  // namespace neuflow::model::vulkan
