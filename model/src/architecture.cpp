#include "neuflow/model/architecture.hpp"

#include <stdexcept>
#include <unordered_set>

#include "network_dims.hpp"

namespace neuflow::model {

namespace {

using Shape = std::vector<int64_t>;

class LayerTable {
 public:
  explicit LayerTable(std::vector<LayerSpec>& layers) : layers_(layers) {}

  void conv(std::string name, int in, int out, int kernel, bool bias, Stage stage, int scale, int runs = 1) {
    layers_.push_back({std::move(name), LayerKind::conv, out, in, kernel, bias, stage, scale, runs});
  }
  void linear(std::string name, int in, int out, bool bias, int runs) {
    layers_.push_back({std::move(name), LayerKind::linear, out, in, 0, bias, Stage::cross_attention, 16, runs});
  }
  void batch_norm(std::string name, int channels, Stage stage) {
    layers_.push_back({std::move(name), LayerKind::batch_norm, channels, channels, 0, true, stage, 8, 0});
  }
  void layer_norm(std::string name, int channels) {
    layers_.push_back(
        {std::move(name), LayerKind::layer_norm, channels, channels, 0, true, Stage::cross_attention, 16, 0});
  }
  // ConvBlock(in -> out, k): conv1 (k x k, no bias), conv2 (3x3, no bias), norm1, norm2.
  void conv_block(const std::string& prefix, int in, int out, int k, Stage stage, int scale) {
    conv(prefix + ".conv1", in, out, k, false, stage, scale);
    conv(prefix + ".conv2", out, out, 3, false, stage, scale);
    batch_norm(prefix + ".norm1", out, stage);
    batch_norm(prefix + ".norm2", out, stage);
  }
  // One cross-attention layer over `dim`-wide tokens, run for both frames.
  void attention_layer(const std::string& prefix, int dim) {
    for (const char* projection : {"q_proj", "k_proj", "v_proj", "merge"}) {
      linear(prefix + "." + projection, dim, dim, true, 2);
    }
    layer_norm(prefix + ".norm1", dim);
    linear(prefix + ".mlp.0", 2 * dim, 2 * dim, false, 2);
    linear(prefix + ".mlp.2", 2 * dim, dim, false, 2);
    layer_norm(prefix + ".norm2", dim);
  }
  // conv3x3 -> GELU -> conv3x3 -> BN, as a Sequential (.0, .2, .3).
  void merge(const std::string& prefix, int in, int out, int runs) {
    conv(prefix + ".0", in, out, 3, false, Stage::merge_s8, 8, runs);
    conv(prefix + ".2", out, out, 3, false, Stage::merge_s8, 8, runs);
    batch_norm(prefix + ".3", out, Stage::merge_s8);
  }
  // Refinement block: its input (correlation, context, hidden state, flow, radius) to the flow
  // update and the next hidden state, run per iteration.
  void refine(const std::string& prefix, int inter, Stage stage, int scale) {
    conv(prefix + ".conv1.conv", kRefineInputChannels, kRefineHiddenWidth, 3, false, stage, scale);
    conv(prefix + ".conv2.conv", kRefineHiddenWidth, inter, 3, false, stage, scale);
    for (int i = 0; i < 5; ++i) {
      conv(prefix + ".conv_layers." + std::to_string(i) + ".conv", inter, inter, 3, false, stage, scale);
    }
    conv(prefix + ".conv3", inter, kRefineOutputChannels, 3, true, stage, scale);
  }

 private:
  std::vector<LayerSpec>& layers_;
};

std::vector<LayerSpec> build_layers() {
  std::vector<LayerSpec> layers;
  LayerTable t(layers);
  constexpr Stage B = Stage::backbone;
  t.conv_block("backbone.block_8_1", 3, 256, 8, B, 8);
  t.conv_block("backbone.block_8_2", 3, 128, 6, B, 8);
  t.conv_block("backbone.block_cat_8", 384, kFeatureChannels, 3, B, 8);
  t.conv_block("backbone.block_16_1", 3, 128, 6, B, 16);
  t.conv_block("backbone.block_8_16", kFeatureChannels, 128, 6, B, 16);
  t.conv_block("backbone.block_cat_16", 256, kBackbone16Channels, 3, B, 16);
  t.attention_layer("cross_attn_s16.layers.0", kFeatureChannels);
  t.attention_layer("cross_attn_s16.layers.1", kFeatureChannels);
  t.batch_norm("cross_attn_s16.norm", kFeatureChannels, Stage::cross_attention);
  t.merge("merge_s8", 2 * kMatchingChannels, kMatchingChannels, 2);  // both frames' features
  t.merge("context_merge_s8", 2 * kContextChannels, kContextChannels, 1);
  t.refine("refine_s16", 128, Stage::refine_s16, 16);
  t.refine("refine_s8", 96, Stage::refine_s8, 8);
  t.conv_block("conv_s8", 3, 128, 8, Stage::upsample_features, 8);
  t.conv("upsample_s8.conv1", 2 + 128, 256, 3, true, Stage::upsampler, 8);  // flow, conv_s8
  t.conv("upsample_s8.conv2", 256, 512, 3, true, Stage::upsampler, 8);
  t.conv("upsample_s8.conv3", 512, kUpsampleMaskChannels, 1, true, Stage::upsampler, 8);
  return layers;
}

// A layer's tensors as torch.save writes them.
void add_tensors(const LayerSpec& layer, std::vector<ParameterSpec>& table) {
  const auto add = [&](const char* suffix, Shape shape, ParameterKind kind = ParameterKind::kParameter) {
    table.push_back({layer.name + suffix, std::move(shape), kind});
  };
  switch (layer.kind) {
    case LayerKind::conv:
      add(".weight", {layer.out, layer.in, layer.kernel, layer.kernel});
      if (layer.bias) add(".bias", {layer.out});
      break;
    case LayerKind::linear:
      add(".weight", {layer.out, layer.in});
      if (layer.bias) add(".bias", {layer.out});
      break;
    case LayerKind::layer_norm:
      add(".weight", {layer.out});
      add(".bias", {layer.out});
      break;
    case LayerKind::batch_norm:
      add(".weight", {layer.out});
      add(".bias", {layer.out});
      add(".running_mean", {layer.out}, ParameterKind::kRunningStat);
      add(".running_var", {layer.out}, ParameterKind::kRunningStat);
      add(".num_batches_tracked", {}, ParameterKind::kBatchCounter);
      break;
  }
}

std::vector<ParameterSpec> build_parameters() {
  std::vector<ParameterSpec> table;
  for (const auto& layer : neuflow_v2_layers()) add_tensors(layer, table);
  return table;
}

}  // namespace

const std::vector<LayerSpec>& neuflow_v2_layers() {
  static const std::vector<LayerSpec> layers = build_layers();
  return layers;
}

const LayerSpec& neuflow_v2_layer(std::string_view name) {
  for (const auto& layer : neuflow_v2_layers()) {
    if (layer.name == name) return layer;
  }
  throw std::out_of_range("NeuFlow-V2 has no layer '" + std::string(name) + "'");
}

const std::vector<ParameterSpec>& neuflow_v2_parameters() {
  static const std::vector<ParameterSpec> table = build_parameters();
  return table;
}

ParameterKind classify_key(std::string_view key) {
  if (key.ends_with(".num_batches_tracked") || key == "num_batches_tracked") {
    return ParameterKind::kBatchCounter;
  }
  if (key.ends_with("running_mean") || key.ends_with("running_var")) {
    return ParameterKind::kRunningStat;
  }
  return ParameterKind::kParameter;
}

ParameterCount count_parameters(const Checkpoint& checkpoint) {
  ParameterCount count;
  for (const auto& [key, tensor] : checkpoint.tensors) {
    (classify_key(key) == ParameterKind::kParameter ? count.parameters : count.buffers) += tensor.numel();
  }
  return count;
}

std::optional<std::string> find_architecture_mismatch(const Checkpoint& checkpoint) {
  const auto& table = neuflow_v2_parameters();
  const std::size_t total = table.size();

  std::size_t missing = 0;
  const ParameterSpec* first_missing = nullptr;
  for (const auto& spec : table) {
    if (checkpoint.find(spec.name) == nullptr && spec.kind != ParameterKind::kBatchCounter) {
      if (first_missing == nullptr) first_missing = &spec;
      ++missing;
    }
  }
  if (first_missing != nullptr) {
    return "missing tensor '" + first_missing->name + "' " + shape_text(first_missing->shape) + " (" +
           std::to_string(missing) + " of NeuFlow-V2's " + std::to_string(total) + " tensors are absent)";
  }

  std::unordered_set<std::string_view> known;
  for (const auto& spec : table) known.insert(spec.name);
  std::size_t unexpected = 0;
  const std::string* first_unexpected = nullptr;
  for (const auto& key : checkpoint.keys) {
    if (!known.contains(key)) {
      if (first_unexpected == nullptr) first_unexpected = &key;
      ++unexpected;
    }
  }
  if (first_unexpected != nullptr) {
    return "unexpected tensor '" + *first_unexpected + "' " + shape_text(checkpoint.at(*first_unexpected).shape) +
           ", not part of NeuFlow-V2 (" + std::to_string(unexpected) + " unexpected tensors)";
  }

  for (const auto& spec : table) {
    const CheckpointTensor* tensor = checkpoint.find(spec.name);
    if (tensor != nullptr && tensor->shape != spec.shape) {
      return "tensor '" + spec.name + "' has shape " + shape_text(tensor->shape) + " but NeuFlow-V2 expects " +
             shape_text(spec.shape);
    }
  }
  return std::nullopt;
}

}  // namespace neuflow::model
