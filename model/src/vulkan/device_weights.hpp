#pragma once
// A model's inference weights on one device: every tensor of NetworkWeights in one storage
// buffer, each layer named by its offset (in floats). Uploaded once per (model, device) and
// shared by every session on that device, as the CPU sessions share the FlowModel.
#include <array>
#include <memory>

#include "neuflow/model/flow_model.hpp"
#include "vulkan/vulkan_device.hpp"
#include "weights.hpp"

namespace neuflow::model::vulkan {

struct DeviceConv {
  int weight = 0;  // OIHW, read as a row-major [out][in·k·k] matrix
  int bias = -1;   // -1: none
  int out_channels = 0, in_channels = 0, kernel = 0;
};

struct DeviceLinear {
  int weight = 0;  // [out][in]
  int bias = -1;
  int out_features = 0, in_features = 0;
};

struct DeviceLayerNorm {
  int gamma = 0, beta = 0;
};

struct DeviceAttentionLayer {
  DeviceLinear q_proj, k_proj, v_proj, merge, mlp0, mlp2;
  DeviceLayerNorm norm1, norm2;
};

struct DeviceBlock {
  DeviceConv conv1, conv2;
};

struct DeviceRefine {
  DeviceConv conv1_dynamic, conv1_constant, conv2, conv3;
  std::array<DeviceConv, 5> conv_layers;
};

struct DeviceWeights {
  std::shared_ptr<const FlowModel> model;  // keeps the key of the sharing registry unique
  std::shared_ptr<VulkanDevice> device;
  bool fp16 = false;  // stored as float16_t (offsets count elements either way)
  Buffer buffer;
  DeviceBlock block_8_1, block_8_2, block_cat_8, block_16_1, block_8_16, block_cat_16, conv_s8;
  std::array<DeviceAttentionLayer, 2> attention;
  int attention_norm_scale = 0, attention_norm_shift = 0;
  DeviceConv merge_s8_0, merge_s8_2, context_merge_s8_0, context_merge_s8_2;
  DeviceRefine refine_s16, refine_s8;
  DeviceConv upsample_conv1, upsample_conv2, upsample_conv3;

  // The weights of `model` on `device` in that precision, uploaded on first use.
  static std::shared_ptr<const DeviceWeights> get(const std::shared_ptr<const FlowModel>& model,
                                                  const std::shared_ptr<VulkanDevice>& device, bool fp16);
};

}  // namespace neuflow::model::vulkan
