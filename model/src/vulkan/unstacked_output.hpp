#pragma once
// A stacked tensor the Vulkan backend never writes: where the cross-attention's last LayerNorm
// writes both frames' tokens into one tensor (frame 0's rows above frame 1's) that only the two
// CopyRows of graph's unstack read, the LayerNorm writes each frame's tokens into that frame's
// tensor itself (layer_norm_params.h), which saves the two copies, a barrier and their bytes.
// Each frame's tensor is then written from the LayerNorm on: the memory plan takes that range
// from planned_live_ranges() (inputs_in_parts.hpp).
#include <array>
#include <cstddef>
#include <optional>

#include "graph/memory_plan.hpp"
#include "graph/ops.hpp"
#include "vulkan/device_weights.hpp"

namespace neuflow::model::vulkan {

struct UnstackedOutput {
  std::array<std::size_t, 2> copies;   // the CopyRows, not recorded: frame 0's, frame 1's
  std::array<graph::Slice, 2> frames;  // where each frame's tokens go, whole tensors
};

// Where the LayerNorm ops[i] writes all of a tensor that only its folded BatchNorm and then two
// CopyRows touch, each taking one half of its rows whole into a tensor of its own that nothing
// touches before it; nothing otherwise.
std::optional<UnstackedOutput> unstacked_output_at(const graph::OpList<DeviceTensor>& ops,
                                                   const graph::TensorTable& tensors, std::size_t i);

// `ranges` with each unstacked frame's tensor of `ops` (which start at op index `first_op`)
// living from its LayerNorm on.
void start_unstacked_frames_early(graph::LiveRanges& ranges, const graph::OpList<DeviceTensor>& ops,
                                  const graph::TensorTable& tensors, int first_op);

}  // namespace neuflow::model::vulkan
