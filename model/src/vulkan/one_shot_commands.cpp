#include "vulkan/one_shot_commands.hpp"

namespace neuflow::model::vulkan {

OneShotCommands::OneShotCommands(VulkanDevice& device) : device_(device) {
  VkCommandPoolCreateInfo pool{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  pool.flags = VK_COMMAND_POOL_CREATE_TRANSIENT_BIT;
  pool.queueFamilyIndex = device.queue_family();
  device.check(vkCreateCommandPool(device.handle(), &pool, nullptr, &pool_), "vkCreateCommandPool");
  VkCommandBufferAllocateInfo alloc{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  alloc.commandPool = pool_;
  alloc.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  alloc.commandBufferCount = 1;
  VkFenceCreateInfo fence{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  try {
    device.check(vkAllocateCommandBuffers(device.handle(), &alloc, &commands_), "vkAllocateCommandBuffers");
    device.check(vkCreateFence(device.handle(), &fence, nullptr, &fence_), "vkCreateFence");
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    device.check(vkBeginCommandBuffer(commands_, &begin), "vkBeginCommandBuffer");
  } catch (...) {
    this->~OneShotCommands();
    throw;
  }
}

OneShotCommands::~OneShotCommands() {
  if (fence_ != VK_NULL_HANDLE) vkDestroyFence(device_.handle(), fence_, nullptr);
  if (pool_ != VK_NULL_HANDLE) vkDestroyCommandPool(device_.handle(), pool_, nullptr);
  fence_ = VK_NULL_HANDLE;
  pool_ = VK_NULL_HANDLE;
}

void OneShotCommands::run() {
  device_.check(vkEndCommandBuffer(commands_), "vkEndCommandBuffer");
  device_.submit_and_wait(commands_, fence_);
}

}  // namespace neuflow::model::vulkan
