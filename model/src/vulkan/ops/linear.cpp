#include <stdexcept>

#include "vulkan/ops/record_op.hpp"

namespace neuflow::model::vulkan {

namespace {

// The members of MatmulParams that MatmulNormParams shares: `w` times the token list `in`
// [features][tokens] into `m` rows of `out` (a product's output, or the LayerNorm's after it).
template <typename Params>
Params token_product(const DeviceLinear& w, int m, const View& in, const View& out, Activation act) {
  const int tokens = in.h * in.w;
  Params p{};
  p.m = m;
  p.n = tokens;
  p.k = w.in_features;
  p.a_off = w.weight.offset;
  p.a_rs = w.in_features;
  p.a_cs = 1;
  p.b_off = in.offset();
  p.b_rs = tokens;
  p.b_cs = 1;
  p.c_off = out.offset();
  p.c_rs = tokens;
  p.c_cs = 1;
  p.bias_off = w.bias.offset;
  p.act = activation_code(act);
  p.alpha = 1.f;
  return p;
}

}  // namespace

// Token lists [features][tokens]: out = act(W · in + b).
void record_op(Recorder& r, const graph::Linear<DeviceTensor>& op) {
  const DeviceLinear& w = *op.weights;
  const View in = r.view(op.in), out = r.view(op.out);
  const int tokens = in.h * in.w;
  const auto p = token_product<MatmulParams>(w, w.out_features, in, out, op.act);
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
  auto p = token_product<MatmulNormParams>(w, last.out_features, in, out, first.act);
  p.res_off = norm.residual ? residual.offset() : -1;
  p.gamma_off = norm.weights->gamma.offset;
  p.beta_off = norm.weights->beta.offset;
  p.scale_off = then ? then->scale->offset : -1;
  p.shift_off = then ? then->shift->offset : -1;
  p.split = unstacked ? tokens / 2 : 0;
  p.out2_off = unstacked ? out2.offset() : 0;
  p.hidden = second ? kMlpHiddenChannels : 0;
  p.w2_off = second ? last.weight.offset : -1;
  p.bias2_off = second ? last.bias.offset : -1;
  p.act2 = second ? activation_code(second->act) : 0;
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
