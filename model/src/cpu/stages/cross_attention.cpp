#include "stages/cross_attention.hpp"

#include <algorithm>

#include "dnnl/matrix_ops.hpp"
#include "ops/layer_norm.hpp"

namespace neuflow::model {

namespace {
// Query rows per attention block: bounds the score block to 1M floats (4 MB) at any resolution.
constexpr int kScoreBlockFloats = 1 << 20;

MatrixView rows(const float* data, int n, int cols, int ld) { return {data, n, cols, ld}; }
}  // namespace

CrossAttention::CrossAttention(const NetworkWeights& weights, int h16, int w16, PlanContext& context)
    : weights_(weights), tokens_(h16 * w16) {
  block_rows_ = std::clamp(kScoreBlockFloats / std::max(tokens_, 1), 1, tokens_);
  const int l = tokens_;
  ScratchArena& arena = context.arena;
  for (Tensor* t : {&q_, &k_, &v_, &message_, &state0_, &state1_}) arena.make_tensor(*t, 1, l, kFeatureChannels);
  arena.make_tensor(scores_, 1, block_rows_, l);
  arena.make_tensor(mlp_in_, 1, l, 2 * kFeatureChannels);
  arena.make_tensor(mlp_hidden_, 1, l, 2 * kFeatureChannels);
}

void CrossAttention::layer(dnnl::stream& stream, const AttentionLayerWeights& w, const float* src, const float* tgt,
                           float* out) {
  const int l = tokens_;
  const auto linear = [&](const float* in, int in_dim, const LinearWeights& lw, float* dst, bool gelu) {
    matmul(stream, rows(in, l, in_dim, in_dim), rows(lw.weight.data(), lw.out_features, lw.in_features, lw.in_features),
           dst, lw.out_features,
           {.transpose_b = true, .bias = lw.bias.empty() ? nullptr : lw.bias.data(), .gelu = gelu});
  };
  linear(src, kFeatureChannels, w.q_proj, q_.data.data(), false);  // already scaled by 1/sqrt(192)
  linear(tgt, kFeatureChannels, w.k_proj, k_.data.data(), false);
  linear(tgt, kFeatureChannels, w.v_proj, v_.data.data(), false);

  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    matmul(
        stream,
        rows(q_.data.data() + static_cast<std::size_t>(r0) * kFeatureChannels, n, kFeatureChannels, kFeatureChannels),
        rows(k_.data.data(), l, kFeatureChannels, kFeatureChannels), scores_.data.data(), l, {.transpose_b = true});
    softmax_rows(stream, scores_.data.data(), n, l);
    matmul(stream, rows(scores_.data.data(), n, l, l), rows(v_.data.data(), l, kFeatureChannels, kFeatureChannels),
           message_.data.data() + static_cast<std::size_t>(r0) * kFeatureChannels, kFeatureChannels);
  }

  // mlp input = concat[src, LayerNorm1(merge(message))]; q_ is free again and holds the merge.
  linear(message_.data.data(), kFeatureChannels, w.merge, q_.data.data(), false);
  stream.wait();
  layer_norm_rows(q_.data.data(), l, kFeatureChannels, w.norm1.gamma, w.norm1.beta);
#pragma omp parallel for
  for (int t = 0; t < l; ++t) {
    float* row = mlp_in_.data.data() + static_cast<std::size_t>(t) * 2 * kFeatureChannels;
    std::copy_n(src + static_cast<std::size_t>(t) * kFeatureChannels, kFeatureChannels, row);
    std::copy_n(q_.data.data() + static_cast<std::size_t>(t) * kFeatureChannels, kFeatureChannels,
                row + kFeatureChannels);
  }

  linear(mlp_in_.data.data(), 2 * kFeatureChannels, w.mlp0, mlp_hidden_.data.data(), true);
  linear(mlp_hidden_.data.data(), 2 * kFeatureChannels, w.mlp2, message_.data.data(), false);
  stream.wait();
  layer_norm_rows(message_.data.data(), l, kFeatureChannels, w.norm2.gamma, w.norm2.beta);
  const std::size_t total = static_cast<std::size_t>(l) * kFeatureChannels;
#pragma omp parallel for
  for (std::size_t i = 0; i < total; ++i) out[i] = src[i] + message_.data[i];
}

void CrossAttention::run(dnnl::stream& stream, const Tensor& f16_0, const Tensor& f16_1, Tensor& out0, Tensor& out1) {
  out0.resize(f16_0.h, f16_0.w, kFeatureChannels);
  out1.resize(f16_1.h, f16_1.w, kFeatureChannels);
  // Layer 0 reads the backbone features, layer 1 reads layer 0's outputs of both frames.
  layer(stream, weights_.attention[0], f16_0.data.data(), f16_1.data.data(), state0_.data.data());
  layer(stream, weights_.attention[0], f16_1.data.data(), f16_0.data.data(), state1_.data.data());
  layer(stream, weights_.attention[1], state0_.data.data(), state1_.data.data(), out0.data.data());
  layer(stream, weights_.attention[1], state1_.data.data(), state0_.data.data(), out1.data.data());

  const auto& scale = weights_.attention_norm_scale;
  const auto& shift = weights_.attention_norm_shift;
  for (Tensor* t : {&out0, &out1}) {
    for (std::size_t p = 0; p < t->pixels(); ++p) {
      float* x = t->data.data() + p * kFeatureChannels;
      for (int c = 0; c < kFeatureChannels; ++c) x[c] = x[c] * scale[c] + shift[c];
    }
  }
}

}  // namespace neuflow::model
