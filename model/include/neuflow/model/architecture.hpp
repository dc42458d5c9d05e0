#pragma once
// NeuFlow-V2's architecture as one table of layers, from which everything else that knows the
// network's shapes is derived: the state dict (every tensor's key and shape, exactly as the
// published checkpoints neuflow_mixed.pth, neuflow_sintel.pth and neuflow_things.pth name
// them, in their file order), the loader's shape checks, and the cost model.
// See shared/docs/neuflow-v2-network.md for what each layer does.
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "neuflow/model/checkpoint.hpp"

namespace neuflow::model {

// Where a layer's work is counted (network_cost.hpp names the same stages).
enum class Stage {
  backbone,           // per frame
  upsample_features,  // conv_s8, per frame
  cross_attention,
  merge_s8,
  refine_s16,
  refine_s8,
  upsampler,
};

enum class LayerKind { conv, linear, batch_norm, layer_norm };

struct LayerSpec {
  std::string name;  // state-dict prefix, e.g. "refine_s8.conv3"
  LayerKind kind = LayerKind::conv;
  int out = 0;     // conv: output channels; linear: output features; norms: channels
  int in = 0;      // conv: input channels; linear: input features
  int kernel = 0;  // conv: square kernel size
  bool bias = false;
  Stage stage = Stage::backbone;
  // conv: its output's scale (8: 1/8 of the model size); linear: its tokens' scale.
  int scale = 8;
  // How often it runs per frame (backbone, upsample_features) or per pair (the rest); the
  // refinements' layers once per iteration.
  int runs = 1;
};

// Every layer, in the order the checkpoints hold their tensors.
const std::vector<LayerSpec>& neuflow_v2_layers();

// The layer named `name`; throws std::out_of_range when the table has none.
const LayerSpec& neuflow_v2_layer(std::string_view name);

enum class ParameterKind {
  kParameter,     // trainable weight or bias (conv, linear, BatchNorm/LayerNorm affine)
  kRunningStat,   // BatchNorm running_mean / running_var (buffers)
  kBatchCounter,  // BatchNorm num_batches_tracked: int64 scalar, unused at inference; may be
                  // absent (checkpoints from PyTorch < 0.4.1 lack it)
};

struct ParameterSpec {
  std::string name;            // state-dict key, e.g. "refine_s8.conv3.bias"
  std::vector<int64_t> shape;  // PyTorch shape: conv [out, in, kh, kw], linear [out, in]
  ParameterKind kind = ParameterKind::kParameter;

  int64_t numel() const {
    int64_t n = 1;
    for (const int64_t d : shape) n *= d;
    return n;
  }
};

// Trainable parameters of NeuFlow-V2 (sum(p.numel() for p in model.parameters())), which is
// the figure the paper and the repository quote. The 17 BatchNorm layers' running statistics
// (5,368 floats) and num_batches_tracked counters (17) are not included.
inline constexpr int64_t kNeuflowV2ParameterCount = 9'029'536;

// The layers' tensors, in the order torch.save writes them: 155 tensors, of which 104
// trainable (kParameter), 34 running statistics and 17 num_batches_tracked counters.
const std::vector<ParameterSpec>& neuflow_v2_parameters();

// The kind of a key by its suffix (running_mean / running_var / num_batches_tracked), for any
// state dict.
ParameterKind classify_key(std::string_view key);

struct ParameterCount {
  int64_t parameters = 0;  // elements of trainable tensors (kParameter)
  int64_t buffers = 0;     // elements of BatchNorm running statistics and counters
};
// Counts the elements of a checkpoint's tensors, classified with classify_key. For a
// NeuFlow-V2 checkpoint: {9'029'536, 5'385} (5,368 running statistics + 17 counters).
ParameterCount count_parameters(const Checkpoint& checkpoint);

// nullopt when `checkpoint` holds exactly NeuFlow-V2's tensors with NeuFlow-V2's shapes
// (num_batches_tracked may be absent; dtypes are not checked, every tensor is float32 after
// loading). Otherwise one readable sentence about the first problem found, checked in this
// order: a missing key (table order), an unexpected key (file order), a wrong shape.
std::optional<std::string> find_architecture_mismatch(const Checkpoint& checkpoint);

}  // namespace neuflow::model
