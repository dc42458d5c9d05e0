#pragma once
// The process's one Vulkan instance, created on first use and kept until exit (an instance
// costs a driver load; devices come and go with the sessions that use them).
#include <vector>

#include "vulkan/vulkan_api.hpp"

namespace neuflow::model::vulkan {

// Throws BackendError(unavailable) naming what is missing (loader, driver).
VkInstance instance();

// The physical devices in the driver's order (the index users give).
std::vector<VkPhysicalDevice> physical_devices();

GpuDevice describe(VkPhysicalDevice device, int index);

}  // namespace neuflow::model::vulkan
