#include "neuflow/model/architecture.hpp"

#include <unordered_set>

namespace neuflow::model {

namespace {

using Shape = std::vector<int64_t>;

class TableBuilder {
 public:
  void add(std::string name, Shape shape, ParameterKind kind = ParameterKind::kParameter) {
    table_.push_back({std::move(name), std::move(shape), kind});
  }
  // BatchNorm2d(channels): affine parameters, running statistics, batch counter.
  void batch_norm(const std::string& prefix, int64_t channels) {
    add(prefix + ".weight", {channels});
    add(prefix + ".bias", {channels});
    add(prefix + ".running_mean", {channels}, ParameterKind::kRunningStat);
    add(prefix + ".running_var", {channels}, ParameterKind::kRunningStat);
    add(prefix + ".num_batches_tracked", {}, ParameterKind::kBatchCounter);
  }
  // ConvBlock(cin -> cout, k): conv1 (k x k, no bias), conv2 (3x3, no bias), norm1, norm2.
  void conv_block(const std::string& prefix, int64_t cin, int64_t cout, int64_t k) {
    add(prefix + ".conv1.weight", {cout, cin, k, k});
    add(prefix + ".conv2.weight", {cout, cout, 3, 3});
    batch_norm(prefix + ".norm1", cout);
    batch_norm(prefix + ".norm2", cout);
  }
  // One cross-attention layer over 192-dim tokens.
  void attention_layer(const std::string& prefix, int64_t dim) {
    for (const char* proj : {"q_proj", "k_proj", "v_proj", "merge"}) {
      add(prefix + "." + proj + ".weight", {dim, dim});
      add(prefix + "." + proj + ".bias", {dim});
    }
    add(prefix + ".norm1.weight", {dim});
    add(prefix + ".norm1.bias", {dim});
    add(prefix + ".mlp.0.weight", {2 * dim, 2 * dim});
    add(prefix + ".mlp.2.weight", {dim, 2 * dim});
    add(prefix + ".norm2.weight", {dim});
    add(prefix + ".norm2.bias", {dim});
  }
  // conv3x3 -> GELU -> conv3x3 -> BN, as a Sequential (.0, .2, .3).
  void merge(const std::string& prefix, int64_t cin, int64_t cout) {
    add(prefix + ".0.weight", {cout, cin, 3, 3});
    add(prefix + ".2.weight", {cout, cout, 3, 3});
    batch_norm(prefix + ".3", cout);
  }
  // Refinement block: 212 input channels, 66 outputs (2 flow + 64 hidden).
  void refine(const std::string& prefix, int64_t inter) {
    add(prefix + ".conv1.conv.weight", {128, 212, 3, 3});
    add(prefix + ".conv2.conv.weight", {inter, 128, 3, 3});
    for (int i = 0; i < 5; ++i) {
      add(prefix + ".conv_layers." + std::to_string(i) + ".conv.weight", {inter, inter, 3, 3});
    }
    add(prefix + ".conv3.weight", {66, inter, 3, 3});
    add(prefix + ".conv3.bias", {66});
  }
  std::vector<ParameterSpec> take() { return std::move(table_); }

 private:
  std::vector<ParameterSpec> table_;
};

std::vector<ParameterSpec> build_table() {
  TableBuilder t;
  t.conv_block("backbone.block_8_1", 3, 256, 8);
  t.conv_block("backbone.block_8_2", 3, 128, 6);
  t.conv_block("backbone.block_cat_8", 384, 192, 3);
  t.conv_block("backbone.block_16_1", 3, 128, 6);
  t.conv_block("backbone.block_8_16", 192, 128, 6);
  t.conv_block("backbone.block_cat_16", 256, 190, 3);
  t.attention_layer("cross_attn_s16.layers.0", 192);
  t.attention_layer("cross_attn_s16.layers.1", 192);
  t.batch_norm("cross_attn_s16.norm", 192);
  t.merge("merge_s8", 256, 128);
  t.merge("context_merge_s8", 128, 64);
  t.refine("refine_s16", 128);
  t.refine("refine_s8", 96);
  t.conv_block("conv_s8", 3, 128, 8);
  t.add("upsample_s8.conv1.weight", {256, 130, 3, 3});
  t.add("upsample_s8.conv1.bias", {256});
  t.add("upsample_s8.conv2.weight", {512, 256, 3, 3});
  t.add("upsample_s8.conv2.bias", {512});
  t.add("upsample_s8.conv3.weight", {576, 512, 1, 1});
  t.add("upsample_s8.conv3.bias", {576});
  return t.take();
}

std::string shape_text(const std::vector<int64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) s += (i ? ", " : "") + std::to_string(shape[i]);
  return s + "]";
}

}  // namespace

const std::vector<ParameterSpec>& neuflow_v2_parameters() {
  static const std::vector<ParameterSpec> table = build_table();
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
    (classify_key(key) == ParameterKind::kParameter ? count.parameters : count.buffers) +=
        tensor.numel();
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
    return "missing tensor '" + first_missing->name + "' " + shape_text(first_missing->shape) +
           " (" + std::to_string(missing) + " of NeuFlow-V2's " + std::to_string(total) +
           " tensors are absent)";
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
    return "unexpected tensor '" + *first_unexpected + "' " +
           shape_text(checkpoint.at(*first_unexpected).shape) + ", not part of NeuFlow-V2 (" +
           std::to_string(unexpected) + " unexpected tensors)";
  }

  for (const auto& spec : table) {
    const CheckpointTensor* tensor = checkpoint.find(spec.name);
    if (tensor != nullptr && tensor->shape != spec.shape) {
      return "tensor '" + spec.name + "' has shape " + shape_text(tensor->shape) +
             " but NeuFlow-V2 expects " + shape_text(spec.shape);
    }
  }
  return std::nullopt;
}

}  // namespace neuflow::model
