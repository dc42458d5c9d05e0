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

}  // namespace neuflow::model::vulkan
