#pragma once
// The Vulkan API as this backend uses it: entry points through volk (the loader is opened at
// run time, so a machine without libvulkan still runs the CPU backend), and every failing call
// turned into a BackendError that names the device and the call.
#include <volk.h>

#include <string>
#include <string_view>

#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::model::vulkan {

// "VK_ERROR_OUT_OF_DEVICE_MEMORY (out of device memory)" and so on.
std::string result_text(VkResult result);

// Throws BackendError("<where>: <call> failed: <result>") unless result is VK_SUCCESS.
void check(VkResult result, std::string_view where, std::string_view call);

}  // namespace neuflow::model::vulkan
