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
  // map_weights()'s function: each host tensor appended, its offset kept; none stays none.
  DeviceTensor operator()(const std::vector<float>& values) {
    return values.empty() ? DeviceTensor{} : DeviceTensor{add(values)};
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
  map_weights(w, p, *d);

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
