#pragma once
// NeuFlow-V2's ops on the graph's tensors. Every backend implements each op once (cpu/ executes,
// vulkan/ records); the network is written once, as a list of them (network_graph.hpp).
//
// Ops that carry weights are templates over what holds a weight tensor (weights.hpp): the host's
// std::vector<float>, a GPU's PackedTensor. Each op lists the slices it reads and writes
// (accesses()), from which the tensors' live ranges and so both backends' memory are planned.
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "graph/activation.hpp"
#include "graph/tensors.hpp"
#include "weights.hpp"

namespace neuflow::model::graph {

// What an op reads and writes. `partial_rows`: its writes may cover only some of a tensor's rows
// (a slice names channels, not rows), so none of them starts the tensor's live range anew.
struct Accesses {
  std::vector<Slice> reads, writes;
  bool partial_rows = false;
};

// The pass's input frame, as the network takes it: [3][H][W] in 0..1. Where it comes from (an
// 8-bit frame, a converted image) is the backend's business.
struct FrameInput {
  Slice out;
  Accesses accesses() const { return {{}, {out}}; }
};

// 2×2 average pooling.
struct AvgPool2x {
  Slice in, out;
  Accesses accesses() const { return {{in}, {out}}; }
};

// out = act(conv(in) + bias (+ addend)); `layer` is the architecture table's name.
template <typename T>
struct Conv2d {
  const BasicConvWeights<T>* weights = nullptr;
  std::string layer;
  Slice in, out;
  int stride = 1, pad = 1;
  Activation act = Activation::none;
  std::optional<Slice> addend;
  Accesses accesses() const { return addend ? Accesses{{in, *addend}, {out}} : Accesses{{in}, {out}}; }
};

// Per token (pixel): out = act(W · in + b).
template <typename T>
struct Linear {
  const BasicLinearWeights<T>* weights = nullptr;
  std::string layer;
  Slice in, out;
  Activation act = Activation::none;
  Accesses accesses() const { return {{in}, {out}}; }
};

// Attention over all tokens: out[:, i] = Σ_j softmax_j(q[:, i] · k[:, j]) v[:, j] (the scale is
// folded into q's projection). `scores` holds a block of `block_rows` rows of it at a time.
// With `across_frames` the tensors hold both frames' tokens (CopyRows: frame 0's rows above
// frame 1's) and each frame's queries attend to the other frame's keys and values.
struct Attention {
  Slice q, k, v, out;
  TensorId scores = -1;
  int block_rows = 1;
  bool across_frames = false;
  Accesses accesses() const { return {{q, k, v}, {{scores, 0, 1}, out}}; }
};

// LayerNorm over each token's channels (+ residual afterwards).
template <typename T>
struct LayerNorm {
  const BasicLayerNormWeights<T>* weights = nullptr;
  std::string layer;
  Slice in, out;
  std::optional<Slice> residual;
  Accesses accesses() const { return residual ? Accesses{{in, *residual}, {out}} : Accesses{{in}, {out}}; }
};

// In place: x = x · scale[c] + shift[c] (a folded BatchNorm).
template <typename T>
struct ChannelAffine {
  const T* scale = nullptr;
  const T* shift = nullptr;
  std::string layer;
  Slice inout;
  Accesses accesses() const { return {{inout}, {inout}}; }
};

// Flow at 1/16 from all-pairs matching: softmax(f0 · f1ᵀ / √c) · grid - grid, in blocks of
// `block_rows` rows of the score matrix.
struct GlobalMatching {
  Slice f0, f1, grid, out;
  TensorId scores = -1, correspondence = -1;
  int block_rows = 1;
  Accesses accesses() const { return {{f0, f1, grid}, {{scores, 0, 1}, {correspondence, 0, 2}, out}}; }
};

// Nearest-neighbour upsampling by `factor` (1: a copy), out = scale · (relu ? max(in, 0) : in).
struct Resample {
  Slice in, out;
  int factor = 1;
  bool relu = false;
  float scale = 1.f;
  Accesses accesses() const { return {{in}, {out}}; }
};

struct Copy {
  Slice in, out;
  Accesses accesses() const { return {{in}, {out}}; }
};

// `rows` rows of in's channels from row `in_row` on into out's from row `out_row` (tensors of one
// width): how both frames' tokens come into one tensor, frame 0's rows above frame 1's, so that
// a token-wise op (Linear, LayerNorm) runs both frames at once, and how they go back.
struct CopyRows {
  Slice in, out;
  int in_row = 0, out_row = 0, rows = 0;
  Accesses accesses() const { return {{in}, {out}, true}; }
};

struct Zero {
  Slice out;
  Accesses accesses() const { return {{}, {out}}; }
};

// The 9×9 window of f0 · f1 around each pixel displaced by the flow, divided by √c.
struct LocalCorrelation {
  Slice f0, f1, flow, out;
  Accesses accesses() const { return {{f0, f1, flow}, {out}}; }
};

// The refinement's step from conv3's output [delta 2, hidden 64]: hidden = clamp(hidden, ±4),
// flow += delta, the new flow also into flow_copy (the next step's input).
struct RefineUpdate {
  Slice update, hidden, flow_copy, flow;
  Accesses accesses() const { return {{update, flow}, {hidden, flow_copy, flow}}; }
};

// Flow at 1/8 to full size: each output pixel a softmax-weighted 3×3 neighbourhood (the 576
// mask channels), times 8.
struct ConvexUpsample {
  Slice mask, flow, out;
  Accesses accesses() const { return {{mask, flow}, {out}}; }
};

// The pass's result, handed to the host.
struct Output {
  Slice flow;
  Accesses accesses() const { return {{flow}, {}}; }
};

// The end of a named stage (stage_observer.hpp): where the timestamps go, and what an observer
// sees there, each tensor under its own name.
struct StageEnd {
  struct Observed {
    std::string name;
    int frame = 0;
    Slice tensor;
  };
  std::string name;
  std::vector<Observed> observed;
  Accesses accesses() const {
    Accesses a;
    for (const auto& o : observed) a.reads.push_back(o.tensor);
    return a;
  }
};

template <typename T>
using Op =
    std::variant<FrameInput, AvgPool2x, Conv2d<T>, Linear<T>, Attention, LayerNorm<T>, ChannelAffine<T>, GlobalMatching,
                 Resample, Copy, CopyRows, Zero, LocalCorrelation, RefineUpdate, ConvexUpsample, Output, StageEnd>;

// An op in a pass. `id` names the op across the passes and the refinements' iterations: each
// iteration repeats the same ops (same ids) on the same tensors, so a backend builds what an op
// needs (a primitive, a pipeline) once per id, however many iterations a pass runs.
template <typename T>
struct Node {
  int id = 0;
  Op<T> op;
};

template <typename T>
using OpList = std::vector<Node<T>>;

// What `op` reads and writes, whichever op it is.
template <typename T>
Accesses accesses_of(const Op<T>& op) {
  return std::visit([](const auto& o) { return o.accesses(); }, op);
}

}  // namespace neuflow::model::graph
