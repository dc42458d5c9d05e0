#pragma once
// A command buffer recorded and run once (uploads at set-up), with its own pool and fence.
#include "vulkan/vulkan_device.hpp"

namespace neuflow::model::vulkan {

class OneShotCommands {
 public:
  explicit OneShotCommands(VulkanDevice& device);
  ~OneShotCommands();
  OneShotCommands(const OneShotCommands&) = delete;
  OneShotCommands& operator=(const OneShotCommands&) = delete;

  VkCommandBuffer buffer() const { return commands_; }
  // Ends recording, submits and waits.
  void run();

 private:
  VulkanDevice& device_;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;
};

}  // namespace neuflow::model::vulkan
