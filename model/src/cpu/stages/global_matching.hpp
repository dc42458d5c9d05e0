#pragma once
// Global matching at 1/16: each pixel's expected position in frame 1 under the softmax of its
// feature similarities, minus its own position. No weights; computed in blocks of rows so
// memory stays O(L · block).
#include <dnnl.hpp>

#include <vector>

#include "ops/feature_ops.hpp"
#include "tensor.hpp"

namespace neuflow::model {

class GlobalMatching {
 public:
  GlobalMatching(int h16, int w16, int channels);

  // f0, f1: [h16, w16, channels] features; flow receives [h16, w16, 2] (x, y displacement).
  void run(dnnl::stream& stream, const ChannelSlice& f0, const ChannelSlice& f1, Tensor& flow);

 private:
  int h_, w_, channels_, block_rows_;
  std::vector<float> a_, b_, grid_, scores_, correspondence_;
};

}  // namespace neuflow::model
