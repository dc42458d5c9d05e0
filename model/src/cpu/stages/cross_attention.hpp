#pragma once
// Two transformer layers at 1/16 in which each frame's tokens attend to the other frame's,
// followed by the BatchNorm `cross_attn_s16.norm`. Attention is computed in blocks of query
// rows, so memory stays O(L · block) instead of O(L²).
#include <dnnl.hpp>

#include "dnnl/plan_context.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class CrossAttention {
 public:
  // Its buffers come from the current region of the context's arena.
  CrossAttention(const NetworkWeights& weights, int h16, int w16, PlanContext& context);

  // f16_0, f16_1: [h16, w16, 192] backbone outputs; out0/out1 receive the normalized results.
  void run(dnnl::stream& stream, const Tensor& f16_0, const Tensor& f16_1, Tensor& out0, Tensor& out1);

 private:
  // out = layer(src, tgt); out must not alias src or tgt.
  void layer(dnnl::stream& stream, const AttentionLayerWeights& w, const float* src, const float* tgt, float* out);

  const NetworkWeights& weights_;
  int tokens_;
  int block_rows_;
  Tensor q_, k_, v_, scores_, message_, mlp_in_, mlp_hidden_, state0_, state1_;  // [1, rows, cols]
};

}  // namespace neuflow::model
