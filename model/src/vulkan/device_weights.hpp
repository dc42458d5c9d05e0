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

// The network's weights as the host holds them (weights.hpp), each tensor an offset here.
struct DeviceWeights : BasicNetworkWeights<DeviceTensor> {
  std::shared_ptr<const FlowModel> model;  // keeps the key of the sharing registry unique
  std::shared_ptr<VulkanDevice> device;
  bool fp16 = false;  // stored as float16_t (offsets count elements either way)
  Buffer buffer;
  // With Winograd: each 3×3 convolution's filters transformed for F(4×4, 3×3) (G g Gᵀ), as
  // [36][out][in] in winograd_buffer, by the offset of its weight. Empty with direct convolutions.
  std::map<int, int> winograd_filters;
  Buffer winograd_buffer;

  // The transformed filters of `conv`, or -1 where it has none.
  int winograd_filters_of(const DeviceConv& conv) const {
    const auto it = winograd_filters.find(conv.weight.offset);
    return it == winograd_filters.end() ? -1 : it->second;
  }

  // The weights of `model` on `device` in that precision, uploaded on first use.
  // winograd: with the transformed filters (conv_algorithm.hpp).
  static std::shared_ptr<const DeviceWeights> get(const std::shared_ptr<const FlowModel>& model,
                                                  const std::shared_ptr<VulkanDevice>& device, bool fp16,
                                                  bool winograd);
};

}  // namespace neuflow::model::vulkan
