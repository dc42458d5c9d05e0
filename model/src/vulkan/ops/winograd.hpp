#pragma once
// Which convolutions the Vulkan backend computes by Winograd F(4×4, 3×3) (conv2d.cpp), and the
// sizes the scratch buffers for them are planned with (vulkan_network_record.cpp).
#include "graph/ops.hpp"
#include "vulkan/device_weights.hpp"

namespace neuflow::model::vulkan {

// A stride-1 3×3 convolution with padding 1 whose filters were transformed at upload.
inline bool takes_winograd(const DeviceWeights& weights, const graph::Conv2d<DeviceTensor>& op) {
  return op.stride == 1 && op.pad == 1 && weights.winograd_filters_of(*op.weights) >= 0;
}

// 4×4 output tiles along a side of `n` pixels.
inline int winograd_tiles(int n) { return (n + 3) / 4; }

}  // namespace neuflow::model::vulkan
