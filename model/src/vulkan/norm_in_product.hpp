#pragma once
// LayerNorms the Vulkan backend records as the epilogue of the product before them
// (matmul_norm_params.h): where a Linear's output is all read by the LayerNorm just after it and
// by nothing else, one dispatch computes both, and the product's output is never written, which
// saves a dispatch, a barrier and that tensor's bytes (the cross-attention's merge and mlp.2,
// each followed by its layer's LayerNorm); in fp16, likewise the MLP's first layer with them. The fused dispatch writes the LayerNorm's output where
// the product runs and reads the product's input until then: the memory plan keeps the two apart
// through planned_live_ranges() (inputs_in_parts.hpp).
#include <cstddef>
#include <optional>

#include "graph/memory_plan.hpp"
#include "graph/ops.hpp"
#include "vulkan/device_weights.hpp"

namespace neuflow::model::vulkan {

// The LayerNorm ops[i + 1] where ops[i] is a Linear whose tile can hold every channel of its
// tokens and that LayerNorm normalizes all of its output; nothing otherwise. Whether anything
// else reads the output is the caller's to check.
std::optional<std::size_t> norm_after_product(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                              std::size_t i);

// The LayerNorm ops[i + 2] where ops[i] and ops[i + 1] are an MLP's two layers (the hidden
// layer's Linear, of kMlpHiddenChannels, and the one that reads all of it) before it, which one
// dispatch can compute with the hidden layer in workgroup memory (matmul_mlp_norm); nothing
// otherwise. Whether anything else reads the products' outputs is the caller's to check.
std::optional<std::size_t> norm_after_mlp(const graph::OpList<DeviceTensor>& ops, const graph::TensorTable& tensors,
                                          std::size_t i);

// `ranges` with the input of each such product (or MLP) of `ops` (which start at op index
// `first_op`) living until its LayerNorm.
void keep_product_inputs_to_norms(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                                  const graph::TensorTable& tensors, int first_op);

}  // namespace neuflow::model::vulkan
