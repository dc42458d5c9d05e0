#pragma once
// A model's inference weights on one device: every tensor of NetworkWeights in one storage
// buffer, each layer named by its offset (in floats). Uploaded once per (model, device) and
// shared by every session on that device, as the CPU sessions share the FlowModel.
#include <array>
#include <map>
#include <memory>

#include "neuflow/model/flow_model.hpp"
#include "vulkan/vulkan_device.hpp"
#include "weights.hpp"

namespace neuflow::model::vulkan {

// A tensor in the weights' buffer.
using DeviceTensor = PackedTensor;

using DeviceConv = BasicConvWeights<DeviceTensor>;  // weight: OIHW, read as a row-major [out][in·k·k]
using DeviceLinear = BasicLinearWeights<DeviceTensor>;
using DeviceLayerNorm = BasicLayerNormWeights<DeviceTensor>;
using DeviceAttentionLayer = BasicAttentionLayerWeights<DeviceTensor>;
using DeviceBlock = BasicConvBlockWeights<DeviceTensor>;
using DeviceRefine = BasicRefineWeights<DeviceTensor>;

// A side of the transformed Winograd filters: `channels` rounded up to a 16×16 fragment's.
constexpr int winograd_filter_side(int channels) { return (channels + 15) / 16 * 16; }

// The network's weights as the host holds them (weights.hpp), each tensor an offset here.
struct DeviceWeights : BasicNetworkWeights<DeviceTensor> {
  std::shared_ptr<const FlowModel> model;  // keeps the key of the sharing registry unique
  std::shared_ptr<VulkanDevice> device;
  bool fp16 = false;  // stored as float16_t (offsets count elements either way)
  Buffer buffer;
  // Where the network runs Winograd products apart from the tile transforms (the split form,
  // and any form on tensor cores): each 3×3 convolution's filters transformed for F(4×4, 3×3)
  // (G g Gᵀ), as [36][out][in] with out and in padded to winograd_filter_side(), at a multiple
  // of 16 values in winograd_buffer, by the offset of its weight. Empty otherwise.
  std::map<int, int> winograd_filters;
  Buffer winograd_buffer;

  // The upsampler's mask convolution (upsample_conv3, 1×1, 576 outputs) with its output rows
  // reordered for convex_upsample_tile.glsl: in tiles of kConvexTileRows rows, tile t holds the
  // 9 neighbours' logits of subpixels 7t .. 7t + 6, row g·9 + k from output channel k·64 + 7t + g;
  // the tiles' last rows (and the last tile's past subpixel 63) zero.
  static constexpr int kConvexTileRows = 64;
  static constexpr int kConvexRows = 640;  // 10 tiles for the 64 subpixels
  DeviceConv convex_mask;

  // The transformed filters of `conv`, or -1 where it has none.
  int winograd_filters_of(const DeviceConv& conv) const {
    const auto it = winograd_filters.find(conv.weight.offset);
    return it == winograd_filters.end() ? -1 : it->second;
  }

  // The weights of `model` on `device` in that precision, uploaded on first use.
  // winograd: with the transformed filters (conv_algorithm.hpp's winograd_filters_at_upload()).
  static std::shared_ptr<const DeviceWeights> get(const std::shared_ptr<const FlowModel>& model,
                                                  const std::shared_ptr<VulkanDevice>& device, bool fp16,
                                                  bool winograd);
};

}  // namespace neuflow::model::vulkan
