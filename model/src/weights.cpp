#include "weights.hpp"

#include <cmath>
#include <string>

namespace neuflow::model {

namespace {

constexpr double kBatchNormEps = 1e-5;

std::string shape_string(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

class WeightReader {
 public:
  explicit WeightReader(const Checkpoint& ckpt) : ckpt_(ckpt) {}

  const std::vector<float>& tensor(const std::string& name, const std::vector<int64_t>& shape) const {
    const auto it = ckpt_.tensors.find(name);
    if (it == ckpt_.tensors.end()) {
      throw CheckpointError(CheckpointError::Kind::kFormat, ckpt_.path + ": missing tensor '" + name + "'");
    }
    if (it->second.shape != shape) {
      throw CheckpointError(CheckpointError::Kind::kFormat, ckpt_.path + ": tensor '" + name + "' has shape " +
                            shape_string(it->second.shape) + ", expected " + shape_string(shape));
    }
    return it->second.data;
  }

  ConvWeights conv(const std::string& prefix, int out, int in, int k, bool bias) const {
    ConvWeights c;
    c.out_channels = out;
    c.in_channels = in;
    c.kernel_h = c.kernel_w = k;
    c.weight = tensor(prefix + ".weight", {out, in, k, k});
    if (bias) c.bias = tensor(prefix + ".bias", {out});
    return c;
  }

  // Per-channel affine form of an inference BatchNorm: y = x * scale + shift.
  void batch_norm(const std::string& prefix, int channels, std::vector<float>& scale,
                  std::vector<float>& shift) const {
    const auto& gamma = tensor(prefix + ".weight", {channels});
    const auto& beta = tensor(prefix + ".bias", {channels});
    const auto& mean = tensor(prefix + ".running_mean", {channels});
    const auto& var = tensor(prefix + ".running_var", {channels});
    scale.resize(channels);
    shift.resize(channels);
    for (int i = 0; i < channels; ++i) {
      const double s = gamma[i] / std::sqrt(static_cast<double>(var[i]) + kBatchNormEps);
      scale[i] = static_cast<float>(s);
      shift[i] = static_cast<float>(beta[i] - mean[i] * s);
    }
  }

  // Folds a BatchNorm into the convolution before it, in double to keep rounding at one step.
  void fold_batch_norm(ConvWeights& c, const std::string& bn_prefix) const {
    const auto& gamma = tensor(bn_prefix + ".weight", {c.out_channels});
    const auto& beta = tensor(bn_prefix + ".bias", {c.out_channels});
    const auto& mean = tensor(bn_prefix + ".running_mean", {c.out_channels});
    const auto& var = tensor(bn_prefix + ".running_var", {c.out_channels});
    const std::size_t per_out = c.weight.size() / c.out_channels;
    std::vector<float> bias(c.out_channels);
    for (int o = 0; o < c.out_channels; ++o) {
      const double s = gamma[o] / std::sqrt(static_cast<double>(var[o]) + kBatchNormEps);
      for (std::size_t i = 0; i < per_out; ++i) {
        float& w = c.weight[o * per_out + i];
        w = static_cast<float>(w * s);
      }
      const double b = c.bias.empty() ? 0.0 : c.bias[o];
      bias[o] = static_cast<float>((b - mean[o]) * s + beta[o]);
    }
    c.bias = std::move(bias);
  }

  ConvBlockWeights conv_block(const std::string& prefix, int in, int out, int k) const {
    ConvBlockWeights b;
    b.conv1 = conv(prefix + ".conv1", out, in, k, false);
    fold_batch_norm(b.conv1, prefix + ".norm1");
    b.conv2 = conv(prefix + ".conv2", out, out, 3, false);
    fold_batch_norm(b.conv2, prefix + ".norm2");
    return b;
  }

  LinearWeights linear(const std::string& prefix, int out, int in, bool bias) const {
    LinearWeights l;
    l.out_features = out;
    l.in_features = in;
    l.weight = tensor(prefix + ".weight", {out, in});
    if (bias) l.bias = tensor(prefix + ".bias", {out});
    return l;
  }

  LayerNormWeights layer_norm(const std::string& prefix, int dim) const {
    return {tensor(prefix + ".weight", {dim}), tensor(prefix + ".bias", {dim})};
  }

  AttentionLayerWeights attention_layer(const std::string& prefix) const {
    constexpr int d = 192;
    AttentionLayerWeights a;
    a.q_proj = linear(prefix + ".q_proj", d, d, true);
    const float scale = static_cast<float>(1.0 / std::sqrt(static_cast<double>(d)));
    for (float& w : a.q_proj.weight) w *= scale;
    for (float& b : a.q_proj.bias) b *= scale;
    a.k_proj = linear(prefix + ".k_proj", d, d, true);
    a.v_proj = linear(prefix + ".v_proj", d, d, true);
    a.merge = linear(prefix + ".merge", d, d, true);
    a.norm1 = layer_norm(prefix + ".norm1", d);
    a.mlp0 = linear(prefix + ".mlp.0", 2 * d, 2 * d, false);
    a.mlp2 = linear(prefix + ".mlp.2", d, 2 * d, false);
    a.norm2 = layer_norm(prefix + ".norm2", d);
    return a;
  }

  RefineWeights refine(const std::string& prefix, int inter) const {
    constexpr int in_total = kCorrChannels + kContextChannels + kHiddenChannels + 2 + 1;  // 212
    RefineWeights r;
    r.inter_dim = inter;
    const ConvWeights full = conv(prefix + ".conv1.conv", 128, in_total, 3, false);
    // Checkpoint input order: corr 0..80, context 81..144, hidden 145..208, flow 209..210, r 211.
    const auto slice = [&](const std::vector<std::pair<int, int>>& ranges) {
      ConvWeights part;
      part.out_channels = 128;
      part.kernel_h = part.kernel_w = 3;
      for (const auto& [begin, end] : ranges) part.in_channels += end - begin;
      part.weight.reserve(static_cast<std::size_t>(128) * part.in_channels * 9);
      for (int o = 0; o < 128; ++o) {
        for (const auto& [begin, end] : ranges) {
          const float* src = full.weight.data() + (static_cast<std::size_t>(o) * in_total + begin) * 9;
          part.weight.insert(part.weight.end(), src, src + static_cast<std::size_t>(end - begin) * 9);
        }
      }
      return part;
    };
    r.conv1_dynamic = slice({{0, 81}, {145, 209}, {209, 211}});
    r.conv1_constant = slice({{81, 145}, {211, 212}});
    r.conv2 = conv(prefix + ".conv2.conv", inter, 128, 3, false);
    for (int i = 0; i < 5; ++i) {
      r.conv_layers[i] = conv(prefix + ".conv_layers." + std::to_string(i) + ".conv", inter, inter, 3, false);
    }
    r.conv3 = conv(prefix + ".conv3", 2 + kHiddenChannels, inter, 3, true);
    return r;
  }

 private:
  const Checkpoint& ckpt_;
};

}  // namespace

NetworkWeights build_network_weights(const Checkpoint& checkpoint) {
  const WeightReader r(checkpoint);
  NetworkWeights n;
  n.block_8_1 = r.conv_block("backbone.block_8_1", 3, 256, 8);
  n.block_8_2 = r.conv_block("backbone.block_8_2", 3, 128, 6);
  n.block_cat_8 = r.conv_block("backbone.block_cat_8", 384, 192, 3);
  n.block_16_1 = r.conv_block("backbone.block_16_1", 3, 128, 6);
  n.block_8_16 = r.conv_block("backbone.block_8_16", 192, 128, 6);
  n.block_cat_16 = r.conv_block("backbone.block_cat_16", 256, 190, 3);
  n.attention[0] = r.attention_layer("cross_attn_s16.layers.0");
  n.attention[1] = r.attention_layer("cross_attn_s16.layers.1");
  r.batch_norm("cross_attn_s16.norm", 192, n.attention_norm_scale, n.attention_norm_shift);
  n.merge_s8_0 = r.conv("merge_s8.0", 128, 256, 3, false);
  n.merge_s8_2 = r.conv("merge_s8.2", 128, 128, 3, false);
  r.fold_batch_norm(n.merge_s8_2, "merge_s8.3");
  n.context_merge_s8_0 = r.conv("context_merge_s8.0", 64, 128, 3, false);
  n.context_merge_s8_2 = r.conv("context_merge_s8.2", 64, 64, 3, false);
  r.fold_batch_norm(n.context_merge_s8_2, "context_merge_s8.3");
  n.refine_s16 = r.refine("refine_s16", 128);
  n.refine_s8 = r.refine("refine_s8", 96);
  n.conv_s8 = r.conv_block("conv_s8", 3, 128, 8);
  n.upsample_conv1 = r.conv("upsample_s8.conv1", 256, 130, 3, true);
  n.upsample_conv2 = r.conv("upsample_s8.conv2", 512, 256, 3, true);
  n.upsample_conv3 = r.conv("upsample_s8.conv3", 576, 512, 1, true);
  return n;
}

}  // namespace neuflow::model
