#pragma once
// NeuFlow-V2's weights in the form inference uses: BatchNorms folded into the convolutions
// before them, the attention's 1/sqrt(d) folded into the query projection, and the
// refinement's first convolution split into the part whose inputs change every iteration
// and the part whose inputs (context, radius plane) are fixed for a pair.
#include <array>
#include <vector>

#include "network_dims.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model {

struct ConvWeights {
  int out_channels = 0;
  int in_channels = 0;
  int kernel_h = 0;
  int kernel_w = 0;
  std::vector<float> weight;  // OIHW
  std::vector<float> bias;    // out_channels values, or empty for no bias
};

struct LinearWeights {
  int out_features = 0;
  int in_features = 0;
  std::vector<float> weight;  // [out, in] row-major
  std::vector<float> bias;    // empty for no bias
};

struct LayerNormWeights {
  std::vector<float> gamma;
  std::vector<float> beta;
};

// conv → BN → LReLU → conv → BN → LReLU, BNs folded.
struct ConvBlockWeights {
  ConvWeights conv1;
  ConvWeights conv2;
};

struct AttentionLayerWeights {
  LinearWeights q_proj;  // scaled by 1/sqrt(192)
  LinearWeights k_proj;
  LinearWeights v_proj;
  LinearWeights merge;
  LayerNormWeights norm1;
  LinearWeights mlp0;  // 384 → 384, no bias
  LinearWeights mlp2;  // 384 → 192, no bias
  LayerNormWeights norm2;
};

struct RefineWeights {
  int inter_dim = 0;
  ConvWeights conv1_dynamic;   // [corr 81, hidden 64, flow 2] → 128
  ConvWeights conv1_constant;  // [context 64, radius 1] → 128
  ConvWeights conv2;
  std::array<ConvWeights, 5> conv_layers;
  ConvWeights conv3;  // → 66, with bias
};

struct NetworkWeights {
  ConvBlockWeights block_8_1, block_8_2, block_cat_8, block_16_1, block_8_16, block_cat_16;
  std::array<AttentionLayerWeights, 2> attention;
  std::vector<float> attention_norm_scale;  // cross_attn_s16.norm as y = x * scale + shift
  std::vector<float> attention_norm_shift;
  ConvWeights merge_s8_0, merge_s8_2;  // merge_s8.3 BN folded into merge_s8_2
  ConvWeights context_merge_s8_0, context_merge_s8_2;
  RefineWeights refine_s16, refine_s8;
  ConvBlockWeights conv_s8;
  ConvWeights upsample_conv1, upsample_conv2, upsample_conv3;
};

// Builds the inference weights from a checkpoint that passed the architecture check.
// Throws CheckpointError naming the tensor if a shape is not as expected.
NetworkWeights build_network_weights(const Checkpoint& checkpoint);

}  // namespace neuflow::model
