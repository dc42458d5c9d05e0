#pragma once
// Everything that depends on one frame only: the backbone (1/8 and 1/16 features) and the
// convex upsampler's image features. In a stream each frame is encoded once and serves two
// consecutive pairs.
#include <dnnl.hpp>

#include <optional>

#include "dnnl/conv_op.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

struct FrameFeatures {
  Tensor f8;                 // [H/8, W/8, 192]: context 0..63, feature 64..191
  Tensor f16;                // [H/16, W/16, 192]: 190 backbone channels + (y - h/2, x - w/2)
  Tensor upsample_features;  // [H/8, W/8, 128]: conv_s8 of the frame
};

class FrameEncoder {
 public:
  // height and width: the model resolution, multiples of 16.
  FrameEncoder(const NetworkWeights& weights, int height, int width, PlanContext& context);

  // image: [height, width, 3], RGB scaled to 0..1; input() or a tensor of the caller's.
  void run(dnnl::stream& stream, const Tensor& image, FrameFeatures& out);

  // [height, width, 3] in the arena, for a frame converted straight into it: alive only until
  // run() has read it.
  Tensor& input() { return input_; }

 private:
  struct Block {
    std::optional<ConvOp> conv1, conv2;
  };
  Block make_block(const ConvBlockWeights& w, int stride, int pad, const dnnl::memory::desc& input,
                   PlanContext& context);
  const dnnl::memory& run_block(dnnl::stream& stream, Block& b, const dnnl::memory& input);

  int height_, width_;
  Tensor input_, half_, quarter_, eighth_, g_;
  Block block_8_1_, block_8_2_, block_cat_8_, block_16_1_, block_8_16_, block_cat_16_, conv_s8_;
  std::optional<dnnl::concat> concat_8_, concat_16_;
  dnnl::memory cat8_, cat16_;
};

}  // namespace neuflow::model
