#pragma once
// NeuFlow-V2's weights in the form inference uses: BatchNorms folded into the convolutions
// before them, the attention's 1/sqrt(d) folded into the query projection, and the
// refinement's first convolution split into the part whose inputs change every iteration
// and the part whose inputs (context, radius plane) are fixed for a pair.
#include <array>
#include <cstddef>
#include <utility>
#include <vector>

#include "network_dims.hpp"
#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model {

// Each layer's weights, generic in what holds a tensor: std::vector<float> on the host
// (NetworkWeights), an offset into one device buffer on a GPU (vulkan/device_weights.hpp). The
// structure is written once here; map_weights() carries a whole network from one holder to
// another, so a backend gets its weights without mirroring these structs.
template <typename T>
struct BasicConvWeights {
  int out_channels = 0;
  int in_channels = 0;
  int kernel_h = 0;
  int kernel_w = 0;
  T weight;  // OIHW
  T bias;    // out_channels values, or empty for no bias
};

template <typename T>
struct BasicLinearWeights {
  int out_features = 0;
  int in_features = 0;
  T weight;  // [out, in] row-major
  T bias;    // empty for no bias
};

template <typename T>
struct BasicLayerNormWeights {
  T gamma;
  T beta;
};

// conv → BN → LReLU → conv → BN → LReLU, BNs folded.
template <typename T>
struct BasicConvBlockWeights {
  BasicConvWeights<T> conv1;
  BasicConvWeights<T> conv2;
};

template <typename T>
struct BasicAttentionLayerWeights {
  // q_proj (scaled by 1/sqrt(192)), k_proj and v_proj stacked: [576, 192]. Each frame's tokens
  // are projected once into all three, which its own queries and the other frame's keys and
  // values both take: one product a frame where there were three.
  BasicLinearWeights<T> qkv_proj;
  BasicLinearWeights<T> merge;
  BasicLayerNormWeights<T> norm1;
  BasicLinearWeights<T> mlp0;  // 384 → 384, no bias
  BasicLinearWeights<T> mlp2;  // 384 → 192, no bias
  BasicLayerNormWeights<T> norm2;
};

template <typename T>
struct BasicRefineWeights {
  int inter_dim = 0;
  BasicConvWeights<T> conv1_dynamic;   // [corr 81, hidden 64, flow 2] → 128
  BasicConvWeights<T> conv1_constant;  // [context 64, radius 1] → 128
  BasicConvWeights<T> conv2;
  std::array<BasicConvWeights<T>, 5> conv_layers;
  BasicConvWeights<T> conv3;  // → 66, with bias
};

template <typename T>
struct BasicNetworkWeights {
  BasicConvBlockWeights<T> block_8_1, block_8_2, block_cat_8, block_16_1, block_8_16, block_cat_16;
  std::array<BasicAttentionLayerWeights<T>, 2> attention;
  T attention_norm_scale;  // cross_attn_s16.norm as y = x * scale + shift
  T attention_norm_shift;
  BasicConvWeights<T> merge_s8_0, merge_s8_2;  // merge_s8.3 BN folded into merge_s8_2
  BasicConvWeights<T> context_merge_s8_0, context_merge_s8_2;
  BasicRefineWeights<T> refine_s16, refine_s8;
  BasicConvBlockWeights<T> conv_s8;
  BasicConvWeights<T> upsample_conv1, upsample_conv2, upsample_conv3;
};

// A tensor's place in one packed buffer (a GPU backend's weights): its offset in elements, or
// -1 where the host had none (a layer without bias).
struct PackedTensor {
  int offset = -1;
};

using ConvWeights = BasicConvWeights<std::vector<float>>;
using LinearWeights = BasicLinearWeights<std::vector<float>>;
using LayerNormWeights = BasicLayerNormWeights<std::vector<float>>;
using ConvBlockWeights = BasicConvBlockWeights<std::vector<float>>;
using AttentionLayerWeights = BasicAttentionLayerWeights<std::vector<float>>;
using RefineWeights = BasicRefineWeights<std::vector<float>>;
// A struct, not an alias, so the public FlowModel header can declare it.
struct NetworkWeights : BasicNetworkWeights<std::vector<float>> {};

// ---- map_weights: every tensor of a network through `f` (const A& → B), shapes kept ----------

// A function with a convolution(from, to) member also sees each convolution whole, once its
// tensors are mapped (to add a form of the filters that only a convolution's shape defines).
template <typename B, typename A, typename F>
BasicConvWeights<B> map_weights(const BasicConvWeights<A>& w, F& f) {
  BasicConvWeights<B> r{w.out_channels, w.in_channels, w.kernel_h, w.kernel_w, f(w.weight), f(w.bias)};
  if constexpr (requires { f.convolution(w, r); }) f.convolution(w, r);
  return r;
}
template <typename B, typename A, typename F>
BasicLinearWeights<B> map_weights(const BasicLinearWeights<A>& w, F& f) {
  return {w.out_features, w.in_features, f(w.weight), f(w.bias)};
}
template <typename B, typename A, typename F>
BasicLayerNormWeights<B> map_weights(const BasicLayerNormWeights<A>& w, F& f) {
  return {f(w.gamma), f(w.beta)};
}
template <typename B, typename A, typename F>
BasicConvBlockWeights<B> map_weights(const BasicConvBlockWeights<A>& w, F& f) {
  return {map_weights<B>(w.conv1, f), map_weights<B>(w.conv2, f)};
}
template <typename B, typename A, typename F>
BasicAttentionLayerWeights<B> map_weights(const BasicAttentionLayerWeights<A>& w, F& f) {
  return {map_weights<B>(w.qkv_proj, f), map_weights<B>(w.merge, f), map_weights<B>(w.norm1, f),
          map_weights<B>(w.mlp0, f),     map_weights<B>(w.mlp2, f),  map_weights<B>(w.norm2, f)};
}
template <typename B, typename A, typename F>
BasicRefineWeights<B> map_weights(const BasicRefineWeights<A>& w, F& f) {
  BasicRefineWeights<B> r{
      w.inter_dim, map_weights<B>(w.conv1_dynamic, f), map_weights<B>(w.conv1_constant, f), map_weights<B>(w.conv2, f),
      {},          map_weights<B>(w.conv3, f)};
  for (std::size_t i = 0; i < w.conv_layers.size(); ++i) r.conv_layers[i] = map_weights<B>(w.conv_layers[i], f);
  return r;
}
// Into `out`, which may be a struct derived from BasicNetworkWeights<B> (with more members).
template <typename B, typename A, typename F>
void map_weights(const BasicNetworkWeights<A>& w, F& f, BasicNetworkWeights<B>& out) {
  for (auto [from, to] : {std::pair{&w.block_8_1, &out.block_8_1}, std::pair{&w.block_8_2, &out.block_8_2},
                          std::pair{&w.block_cat_8, &out.block_cat_8}, std::pair{&w.block_16_1, &out.block_16_1},
                          std::pair{&w.block_8_16, &out.block_8_16}, std::pair{&w.block_cat_16, &out.block_cat_16},
                          std::pair{&w.conv_s8, &out.conv_s8}}) {
    *to = map_weights<B>(*from, f);
  }
  for (std::size_t i = 0; i < w.attention.size(); ++i) out.attention[i] = map_weights<B>(w.attention[i], f);
  out.attention_norm_scale = f(w.attention_norm_scale);
  out.attention_norm_shift = f(w.attention_norm_shift);
  for (auto [from, to] :
       {std::pair{&w.merge_s8_0, &out.merge_s8_0}, std::pair{&w.merge_s8_2, &out.merge_s8_2},
        std::pair{&w.context_merge_s8_0, &out.context_merge_s8_0},
        std::pair{&w.context_merge_s8_2, &out.context_merge_s8_2}, std::pair{&w.upsample_conv1, &out.upsample_conv1},
        std::pair{&w.upsample_conv2, &out.upsample_conv2}, std::pair{&w.upsample_conv3, &out.upsample_conv3}}) {
    *to = map_weights<B>(*from, f);
  }
  out.refine_s16 = map_weights<B>(w.refine_s16, f);
  out.refine_s8 = map_weights<B>(w.refine_s8, f);
}

// Builds the inference weights from a checkpoint that passed the architecture check.
// Throws CheckpointError naming the tensor if a shape is not as expected.
NetworkWeights build_network_weights(const Checkpoint& checkpoint);

}  // namespace neuflow::model
