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

namespace {

// A product's LayerNorm epilogue (matmul_norm_params.h): `first` the product that reads the
// input (the MLP's first layer where `second` is its second), `norm` what normalizes the last
// product's output. Records the dispatch; `multiply_adds` are the products'.
void record_norm_epilogue(Recorder& r, const graph::Linear<DeviceTensor>& first,
                          const graph::Linear<DeviceTensor>* second, const graph::LayerNorm<DeviceTensor>& norm,
                          const graph::ChannelAffine<DeviceTensor>* then, const UnstackedOutput* unstacked) {
  const DeviceLinear& w = *first.weights;
  const DeviceLinear& last = second ? *second->weights : w;
  const graph::Linear<DeviceTensor>& normalized = second ? *second : first;
  if (last.out_features != kMatmulNormChannels || norm.in.tensor != normalized.out.tensor ||
      (second && (w.out_features != kMlpHiddenChannels || last.in_features != kMlpHiddenChannels))) {
    throw std::logic_error("the Vulkan " + normalized.layer + " cannot take " + norm.layer + " as its epilogue");
  }
  const View in = r.view(first.in);
  const View out = r.view(unstacked ? unstacked->frames[0] : norm.out);
  const View out2 = unstacked ? r.view(unstacked->frames[1]) : View{};
  const View residual = norm.residual ? r.view(*norm.residual) : View{};
  const int tokens = in.h * in.w;
  const MatmulNormParams p{last.out_features,
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
                           activation_code(first.act),
                           1.f,
                           norm.residual ? residual.offset() : -1,
                           norm.weights->gamma.offset,
                           norm.weights->beta.offset,
                           then ? then->scale->offset : -1,
                           then ? then->shift->offset : -1,
                           unstacked ? tokens / 2 : 0,
                           unstacked ? out2.offset() : 0,
                           second ? kMlpHiddenChannels : 0,
                           second ? last.weight.offset : -1,
                           second ? last.bias.offset : -1,
                           second ? activation_code(second->act) : 0};
  const auto weights_of = [](const DeviceLinear& l) {
    return static_cast<long long>(l.out_features) * l.in_features + (l.bias.offset >= 0 ? l.out_features : 0);
  };
  const long long products = static_cast<long long>(w.out_features) * w.in_features +
                             (second ? static_cast<long long>(last.out_features) * last.in_features : 0);
  const long long written = static_cast<long long>(last.out_features) * tokens;
  const long long read = weights_of(w) + (second ? weights_of(last) : 0) + in.count() +
                         (then ? 4LL : 2LL) * last.out_features + (norm.residual ? written : 0);
  constexpr GemmTile kEveryRow{kMatmulNormChannels / 16, 1};
  const std::array<const Buffer*, kShaderBindings> bindings{&r.weights(), in.buffer, out.buffer, residual.buffer,
                                                            out2.buffer};
  const Work work{r.bytes(read), r.bytes(written), products * tokens};
  if (second) {
    r.product<Shader::matmul_mlp_norm>(bindings, p, work, last.out_features, tokens, "attention", 1, kEveryRow);
  } else {
    r.product<Shader::matmul_norm>(bindings, p, work, last.out_features, tokens, "attention", 1, kEveryRow);
  }
}

}  // namespace

void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op, const graph::LayerNorm<DeviceTensor>& norm,
               const graph::ChannelAffine<DeviceTensor>* then, const UnstackedOutput* unstacked) {
  record_norm_epilogue(r, op, nullptr, norm, then, unstacked);
}

void record_op(Recorder& r, const graph::Linear<DeviceTensor>& first, const graph::Linear<DeviceTensor>& second,
               const graph::LayerNorm<DeviceTensor>& norm, const graph::ChannelAffine<DeviceTensor>* then,
               const UnstackedOutput* unstacked) {
  if (!r.fp16())
    throw std::logic_error("the Vulkan " + first.layer + " and " + second.layer + " are one dispatch only in fp16");
  record_norm_epilogue(r, first, &second, norm, then, unstacked);
}

}  // namespace neuflow::model::vulkan
