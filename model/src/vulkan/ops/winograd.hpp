#pragma once
// Which convolutions the Vulkan backend computes by Winograd F(4×4, 3×3) (conv2d.cpp), and the
// sizes the scratch buffers for them are planned with (vulkan_network_record.cpp).
#include "graph/ops.hpp"
#include "vulkan/conv_algorithm.hpp"
#include "vulkan/device_weights.hpp"

namespace neuflow::model::vulkan {

// 4×4 output tiles along a side of `n` pixels.
inline int winograd_tiles(int n) { return (n + 3) / 4; }

// A stride-1 3×3 convolution with padding 1, where the network takes Winograd at all, with an
// output (height × width) large enough for Winograd to do less work as the products are
// tiled: 36 point products over the 4×4 tiles in 64-column workgroups against the direct
// convolution's 9 taps over the pixels in the same workgroups. At 1/8 of 64×64 (64 pixels, 4
// tiles) Winograd would run 36 workgroups where the direct convolution runs 9: 3.3× slower a
// frame on lavapipe; at 1/8 of 256×192 it runs a third of the work.
inline bool takes_winograd(ConvAlgorithm conv, const graph::Conv2d<DeviceTensor>& op, int out_h, int out_w) {
  if (conv == ConvAlgorithm::direct || op.stride != 1 || op.pad != 1) return false;
  if (op.weights->kernel_h != 3 || op.weights->kernel_w != 3) return false;
  const long pixels = static_cast<long>(out_h) * out_w;
  const long tiles = static_cast<long>(winograd_tiles(out_h)) * winograd_tiles(out_w);
  return 36 * ((tiles + 63) / 64) < 9 * ((pixels + 63) / 64);
}

}  // namespace neuflow::model::vulkan
