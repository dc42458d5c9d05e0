#pragma once
// Convex upsampling of the 1/8 flow to full resolution: a mask head predicts, for each of the
// 8×8 output pixels of a coarse pixel, softmax weights over its 3×3 coarse neighbourhood.
// The head's last layer (1×1, 512 → 576 logits per coarse pixel), the softmax and the
// weighted sum run band by band of coarse rows, so the whole-frame mask (576 floats per
// coarse pixel: 75 MB at 1920×1088) is never held; a band stays in cache across the passes.
#include <dnnl.hpp>

#include <optional>
#include <vector>

#include "dnnl/conv_op.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class ConvexUpsampler {
 public:
  ConvexUpsampler(const NetworkWeights& weights, int h8, int w8, PlanContext& context);

  // flow8 [h8, w8, 2], image_features [h8, w8, 128] (conv_s8 of frame 0) → flow [8·h8, 8·w8, 2].
  // The result is in the arena, valid until another stage runs.
  const Tensor& run(dnnl::stream& stream, const Tensor& flow8, const Tensor& image_features);

 private:
  Tensor input_, flow_;
  std::optional<ConvOp> conv1_, conv2_;  // conv2 writes NHWC: rows of 512 features per pixel
  const ConvWeights* mask_head_;         // the 1×1 512 → 576 layer, [576][512] row-major
  int band_rows_;
  std::vector<float> band_;  // one band's logits: [pixels][9 · 64]
};

}  // namespace neuflow::model
