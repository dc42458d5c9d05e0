#pragma once
// Global matching at 1/16: each pixel's expected position in frame 1 under the softmax of its
// feature similarities, minus its own position. No weights; computed in blocks of rows so
// memory stays O(L · block).
#include <dnnl.hpp>

#include <vector>

#include "dnnl/plan_context.hpp"
#include "ops/feature_ops.hpp"
#include "tensor.hpp"

namespace neuflow::model {

class GlobalMatching {
 public:
  // The features' copies and the score block come from the current region of the context's arena.
  GlobalMatching(int h16, int w16, int channels, PlanContext& context);

  // f0, f1: [h16, w16, channels] features; flow receives [h16, w16, 2] (x, y displacement).
  void run(dnnl::stream& stream, const ChannelSlice& f0, const ChannelSlice& f1, Tensor& flow);

 private:
  int h_, w_, channels_, block_rows_;
  Tensor a_, b_, scores_;  // [1, rows, cols]
  std::vector<float> grid_, correspondence_;
};

}  // namespace neuflow::model
