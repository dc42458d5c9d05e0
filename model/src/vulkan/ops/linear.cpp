#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

// Token lists [features][tokens]: out = act(W · in + b).
void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op) {
  const DeviceLinear& w = *op.weights;
  const View in = r.view(op.in), out = r.view(op.out);
  const int tokens = in.h * in.w;
  const MatmulParams p{w.out_features,
                       tokens,
                       w.in_features,
                       w.weight.offset,
                       w.in_features,
                       1,
                       in.offset(),
                       tokens,
                       1,
                       out.offset(),
                       tokens,
                       1,
                       w.bias.offset,
                       activation_code(op.act),
                       1.f};
  const long long weights = static_cast<long long>(w.out_features) * w.in_features;
  const long long read = weights + (w.bias.offset >= 0 ? w.out_features : 0) + in.count();
  r.product<Shader::matmul>({&r.weights(), in.buffer, out.buffer, nullptr}, p,
                            {r.bytes(read), r.bytes(out.count()), weights * tokens}, w.out_features, tokens,
                            "attention");
}

void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op, const graph::LayerNorm<DeviceTensor>& norm,
               const graph::ChannelAffine<DeviceTensor>* then, const UnstackedOutput* unstacked) {
  const DeviceLinear& w = *op.weights;
  if (w.out_features != kMatmulNormChannels || norm.in.tensor != op.out.tensor) {
    throw std::logic_error("the Vulkan " + op.layer + " cannot take " + norm.layer + " as its epilogue");
  }
  const View in = r.view(op.in);
  const View out = r.view(unstacked ? unstacked->frames[0] : norm.out);
  const View out2 = unstacked ? r.view(unstacked->frames[1]) : View{};
  const View residual = norm.residual ? r.view(*norm.residual) : View{};
  const int tokens = in.h * in.w;
  const MatmulNormParams p{w.out_features,
                           tokens,
                           w.in_features,
                           w.weight.offset,
                           w.in_features,
                           1,
                           in.offset(),
                           tokens,
                           1,
                           out.offset(),
                           tokens,
                           1,
                           w.bias.offset,
                           activation_code(op.act),
                           1.f,
                           norm.residual ? residual.offset() : -1,
                           norm.weights->gamma.offset,
                           norm.weights->beta.offset,
                           then ? then->scale->offset : -1,
                           then ? then->shift->offset : -1,
                           unstacked ? tokens / 2 : 0,
                           unstacked ? out2.offset() : 0};
  const long long weights = static_cast<long long>(w.out_features) * w.in_features;
  const long long written = static_cast<long long>(w.out_features) * tokens;
  const long long read = weights + (w.bias.offset >= 0 ? w.out_features : 0) + in.count() +
                         (then ? 4LL : 2LL) * w.out_features + (norm.residual ? written : 0);
  constexpr GemmTile kEveryRow{kMatmulNormChannels / 16, 1};
  r.product<Shader::matmul_norm>({&r.weights(), in.buffer, out.buffer, residual.buffer, out2.buffer}, p,
                                 {r.bytes(read), r.bytes(written), weights * tokens}, w.out_features, tokens,
                                 "attention", 1, kEveryRow);
}

}  // namespace neuflow::model::vulkan
