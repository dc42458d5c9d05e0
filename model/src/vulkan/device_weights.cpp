#include "vulkan/device_weights.hpp"

#include <cstring>
#include <map>
#include <mutex>
#include <tuple>
#include <vector>

#include "vulkan/half_float.hpp"
#include "vulkan/one_shot_commands.hpp"

namespace neuflow::model::vulkan {

namespace {

// Lays every tensor out in one host vector; offsets are in floats.
class Packer {
 public:
  int add(const std::vector<float>& values) {
    const int offset = static_cast<int>(data.size());
    data.insert(data.end(), values.begin(), values.end());
    // 4-float alignment keeps every tensor's start 16-byte aligned (vector loads on some GPUs).
    while (data.size() % 4 != 0) data.push_back(0.f);
    return offset;
  }
  DeviceConv conv(const ConvWeights& w) {
    DeviceConv d;
    d.weight = add(w.weight);
    d.bias = w.bias.empty() ? -1 : add(w.bias);
    d.out_channels = w.out_channels;
    d.in_channels = w.in_channels;
    d.kernel = w.kernel_h;
    return d;
  }
  DeviceLinear linear(const LinearWeights& w) {
    DeviceLinear d;
    d.weight = add(w.weight);
    d.bias = w.bias.empty() ? -1 : add(w.bias);
    d.out_features = w.out_features;
    d.in_features = w.in_features;
    return d;
  }
  DeviceLayerNorm norm(const LayerNormWeights& w) { return {add(w.gamma), add(w.beta)}; }
  DeviceBlock block(const ConvBlockWeights& w) { return {conv(w.conv1), conv(w.conv2)}; }
  DeviceRefine refine(const RefineWeights& w) {
    DeviceRefine r;
    r.conv1_dynamic = conv(w.conv1_dynamic);
    r.conv1_constant = conv(w.conv1_constant);
    r.conv2 = conv(w.conv2);
    for (std::size_t i = 0; i < w.conv_layers.size(); ++i) r.conv_layers[i] = conv(w.conv_layers[i]);
    r.conv3 = conv(w.conv3);
    return r;
  }
  std::vector<float> data;
};

std::shared_ptr<const DeviceWeights> upload(const std::shared_ptr<const FlowModel>& model,
                                            const std::shared_ptr<VulkanDevice>& device, bool fp16) {
  const NetworkWeights& w = model->weights();
  auto d = std::make_shared<DeviceWeights>();
  d->model = model;
  d->device = device;
  d->fp16 = fp16;
  Packer p;
  d->block_8_1 = p.block(w.block_8_1);
  d->block_8_2 = p.block(w.block_8_2);
  d->block_cat_8 = p.block(w.block_cat_8);
  d->block_16_1 = p.block(w.block_16_1);
  d->block_8_16 = p.block(w.block_8_16);
  d->block_cat_16 = p.block(w.block_cat_16);
  d->conv_s8 = p.block(w.conv_s8);
  for (std::size_t i = 0; i < w.attention.size(); ++i) {
    const auto& a = w.attention[i];
    auto& o = d->attention[i];
    o.q_proj = p.linear(a.q_proj);
    o.k_proj = p.linear(a.k_proj);
    o.v_proj = p.linear(a.v_proj);
    o.merge = p.linear(a.merge);
    o.norm1 = p.norm(a.norm1);
    o.mlp0 = p.linear(a.mlp0);
    o.mlp2 = p.linear(a.mlp2);
    o.norm2 = p.norm(a.norm2);
  }
  d->attention_norm_scale = p.add(w.attention_norm_scale);
  d->attention_norm_shift = p.add(w.attention_norm_shift);
  d->merge_s8_0 = p.conv(w.merge_s8_0);
  d->merge_s8_2 = p.conv(w.merge_s8_2);
  d->context_merge_s8_0 = p.conv(w.context_merge_s8_0);
  d->context_merge_s8_2 = p.conv(w.context_merge_s8_2);
  d->refine_s16 = p.refine(w.refine_s16);
  d->refine_s8 = p.refine(w.refine_s8);
  d->upsample_conv1 = p.conv(w.upsample_conv1);
  d->upsample_conv2 = p.conv(w.upsample_conv2);
  d->upsample_conv3 = p.conv(w.upsample_conv3);

  const std::size_t bytes = p.data.size() * (fp16 ? 2 : 4);
  d->buffer = device->create_buffer(bytes, VulkanDevice::Memory::device, "the model's weights");
  Buffer staging = device->create_buffer(bytes, VulkanDevice::Memory::upload, "uploading the model's weights");
  if (fp16) {
    auto* out = static_cast<std::uint16_t*>(static_cast<void*>(staging.mapped()));
    for (std::size_t i = 0; i < p.data.size(); ++i) out[i] = to_half(p.data[i]);
  } else {
    std::memcpy(staging.mapped(), p.data.data(), bytes);
  }
  OneShotCommands commands(*device);
  const VkBufferCopy region{0, 0, bytes};
  vkCmdCopyBuffer(commands.buffer(), staging.handle(), d->buffer.handle(), 1, &region);
  commands.run();
  return d;
}

}  // namespace

std::shared_ptr<const DeviceWeights> DeviceWeights::get(const std::shared_ptr<const FlowModel>& model,
                                                        const std::shared_ptr<VulkanDevice>& device, bool fp16) {
  static std::mutex mutex;
  static std::map<std::tuple<const FlowModel*, const VulkanDevice*, bool>, std::weak_ptr<const DeviceWeights>> uploaded;
  const std::lock_guard lock(mutex);
  auto& slot = uploaded[{model.get(), device.get(), fp16}];
  if (auto existing = slot.lock()) return existing;
  auto weights = upload(model, device, fp16);
  slot = weights;
  return weights;
}

}  // namespace neuflow::model::vulkan
