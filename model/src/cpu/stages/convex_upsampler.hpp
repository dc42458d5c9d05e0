#pragma once
// Convex upsampling of the 1/8 flow to full resolution: a mask head predicts, for each of the
// 8×8 output pixels of a coarse pixel, softmax weights over its 3×3 coarse neighbourhood.
#include <dnnl.hpp>

#include <optional>

#include "dnnl/conv_op.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class ConvexUpsampler {
 public:
  ConvexUpsampler(const NetworkWeights& weights, int h8, int w8, PlanContext& context);

  // flow8 [h8, w8, 2], image_features [h8, w8, 128] (conv_s8 of frame 0) → flow [8·h8, 8·w8, 2].
  void run(dnnl::stream& stream, const Tensor& flow8, const Tensor& image_features, Tensor& flow);

 private:
  Tensor input_;
  std::optional<ConvOp> conv1_, conv2_, conv3_;
};

}  // namespace neuflow::model
