#include "weights.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "neuflow/model/architecture.hpp"

namespace neuflow::model {

namespace {

constexpr double kBatchNormEps = 1e-5;

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
                                                                shape_text(it->second.shape) + ", expected " +
                                                                shape_text(shape));
    }
    return it->second.data;
  }

  // Shapes come from the architecture table; a layer missing from it is a bug here.
  static const LayerSpec& layer(const std::string& name, LayerKind kind) {
    const LayerSpec& spec = neuflow_v2_layer(name);
    if (spec.kind != kind) throw std::logic_error(name + " is not the kind of layer the loader reads it as");
    return spec;
  }

  ConvWeights conv(const std::string& name) const {
    const LayerSpec& spec = layer(name, LayerKind::conv);
    return {spec.out,
            spec.in,
            spec.kernel,
            spec.kernel,
            tensor(name + ".weight", {spec.out, spec.in, spec.kernel, spec.kernel}),
            bias(name, spec)};
  }

  std::vector<float> bias(const std::string& layer_name, const LayerSpec& spec) const {
    return spec.bias ? tensor(layer_name + ".bias", {spec.out}) : std::vector<float>{};
  }

  // Per-channel affine form of an inference BatchNorm: y = x * scale + shift.
  void batch_norm(const std::string& prefix, std::vector<float>& scale, std::vector<float>& shift) const {
    const int channels = layer(prefix, LayerKind::batch_norm).out;
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
    if (layer(bn_prefix, LayerKind::batch_norm).out != c.out_channels) {
      throw std::logic_error(bn_prefix + " does not follow a convolution of its width");
    }
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

  ConvBlockWeights conv_block(const std::string& prefix) const {
    ConvBlockWeights b;
    b.conv1 = conv(prefix + ".conv1");
    fold_batch_norm(b.conv1, prefix + ".norm1");
    b.conv2 = conv(prefix + ".conv2");
    fold_batch_norm(b.conv2, prefix + ".norm2");
    return b;
  }

  LinearWeights linear(const std::string& name) const {
    const LayerSpec& spec = layer(name, LayerKind::linear);
    return {spec.out, spec.in, tensor(name + ".weight", {spec.out, spec.in}), bias(name, spec)};
  }

  // Linear layers of one input size as one, their outputs one after the other; a layer without
  // a bias contributes zeros where the others have one.
  static LinearWeights stacked(const std::vector<LinearWeights>& layers) {
    LinearWeights s{0, layers.front().in_features, {}, {}};
    const bool any_bias = std::any_of(layers.begin(), layers.end(), [](const auto& l) { return !l.bias.empty(); });
    for (const LinearWeights& l : layers) {
      s.out_features += l.out_features;
      s.weight.insert(s.weight.end(), l.weight.begin(), l.weight.end());
      if (!any_bias) continue;
      if (l.bias.empty()) {
        s.bias.insert(s.bias.end(), static_cast<std::size_t>(l.out_features), 0.f);
      } else {
        s.bias.insert(s.bias.end(), l.bias.begin(), l.bias.end());
      }
    }
    return s;
  }

  LayerNormWeights layer_norm(const std::string& name) const {
    const int dim = layer(name, LayerKind::layer_norm).out;
    return {tensor(name + ".weight", {dim}), tensor(name + ".bias", {dim})};
  }

  AttentionLayerWeights attention_layer(const std::string& prefix) const {
    AttentionLayerWeights a;
    LinearWeights q = linear(prefix + ".q_proj");
    const float scale = static_cast<float>(1.0 / std::sqrt(static_cast<double>(q.in_features)));
    for (float& w : q.weight) w *= scale;
    for (float& b : q.bias) b *= scale;
    a.qkv_proj = stacked({q, linear(prefix + ".k_proj"), linear(prefix + ".v_proj")});
    a.merge = linear(prefix + ".merge");
    a.norm1 = layer_norm(prefix + ".norm1");
    a.mlp0 = linear(prefix + ".mlp.0");
    a.mlp2 = linear(prefix + ".mlp.2");
    a.norm2 = layer_norm(prefix + ".norm2");
    return a;
  }

  RefineWeights refine(const std::string& prefix) const {
    constexpr int in_total = kRefineInputChannels;
    // Checkpoint input order: corr, context, hidden, flow (2), radius (1).
    constexpr int corr = 0, context = corr + kCorrChannels, hidden = context + kContextChannels,
                  flow = hidden + kHiddenChannels, radius = flow + 2;
    RefineWeights r;
    const ConvWeights full = conv(prefix + ".conv1.conv");
    if (full.in_channels != in_total) throw std::logic_error(prefix + ": the refinement's inputs changed");
    const auto slice = [&](const std::vector<std::pair<int, int>>& ranges) {
      ConvWeights part;
      part.out_channels = full.out_channels;
      part.kernel_h = part.kernel_w = 3;
      for (const auto& [begin, end] : ranges) part.in_channels += end - begin;
      part.weight.reserve(static_cast<std::size_t>(full.out_channels) * part.in_channels * 9);
      for (int o = 0; o < full.out_channels; ++o) {
        for (const auto& [begin, end] : ranges) {
          const float* src = full.weight.data() + (static_cast<std::size_t>(o) * in_total + begin) * 9;
          part.weight.insert(part.weight.end(), src, src + static_cast<std::size_t>(end - begin) * 9);
        }
      }
      return part;
    };
    r.conv1_dynamic = slice({{corr, context}, {hidden, flow}, {flow, radius}});
    r.conv1_constant = slice({{context, hidden}, {radius, in_total}});
    r.conv2 = conv(prefix + ".conv2.conv");
    r.inter_dim = r.conv2.out_channels;
    for (int i = 0; i < 5; ++i) r.conv_layers[i] = conv(prefix + ".conv_layers." + std::to_string(i) + ".conv");
    r.conv3 = conv(prefix + ".conv3");
    return r;
  }

 private:
  const Checkpoint& ckpt_;
};

}  // namespace

NetworkWeights build_network_weights(const Checkpoint& checkpoint) {
  const WeightReader r(checkpoint);
  NetworkWeights n;
  for (auto [block, name] : {std::pair{&n.block_8_1, "block_8_1"}, std::pair{&n.block_8_2, "block_8_2"},
                             std::pair{&n.block_cat_8, "block_cat_8"}, std::pair{&n.block_16_1, "block_16_1"},
                             std::pair{&n.block_8_16, "block_8_16"}, std::pair{&n.block_cat_16, "block_cat_16"}}) {
    *block = r.conv_block(std::string("backbone.") + name);
  }
  n.attention[0] = r.attention_layer("cross_attn_s16.layers.0");
  n.attention[1] = r.attention_layer("cross_attn_s16.layers.1");
  r.batch_norm("cross_attn_s16.norm", n.attention_norm_scale, n.attention_norm_shift);
  n.merge_s8_0 = r.conv("merge_s8.0");
  n.merge_s8_2 = r.conv("merge_s8.2");
  r.fold_batch_norm(n.merge_s8_2, "merge_s8.3");
  n.context_merge_s8_0 = r.conv("context_merge_s8.0");
  n.context_merge_s8_2 = r.conv("context_merge_s8.2");
  r.fold_batch_norm(n.context_merge_s8_2, "context_merge_s8.3");
  n.refine_s16 = r.refine("refine_s16");
  n.refine_s8 = r.refine("refine_s8");
  n.conv_s8 = r.conv_block("conv_s8");
  for (auto [conv, name] : {std::pair{&n.upsample_conv1, "conv1"}, std::pair{&n.upsample_conv2, "conv2"},
                            std::pair{&n.upsample_conv3, "conv3"}}) {
    *conv = r.conv(std::string("upsample_s8.") + name);
  }
  return n;
}

}  // namespace neuflow::model
