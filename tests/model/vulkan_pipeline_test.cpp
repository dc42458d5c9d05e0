// Every shader, in both precisions, makes a pipeline that the driver and the validation layer
// accept: a check of each SPIR-V module the build's shader compiler produced, without running
// the network (glslang 11, Ubuntu 22.04's glslangValidator, once produced an invalid fp16 one:
// a 16-bit constant without the Float16 capability).
#include <gtest/gtest.h>

#include <cstddef>

#include "support/vulkan.hpp"
#include "vulkan/shaders.hpp"
#include "vulkan/vulkan_device.hpp"

namespace neuflow::model::vulkan {
namespace {

TEST(VulkanPipelines, EveryShaderInBothPrecisionsIsAcceptedByTheDriverAndTheValidationLayer) {
  NEUFLOW_REQUIRE_VULKAN();
  const auto device = VulkanDevice::open(0);
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    const auto shader = static_cast<Shader>(i);
    EXPECT_NE(device->pipeline(shader, false), VK_NULL_HANDLE) << shader_name(shader);
    if (device->info().fp16) {
      EXPECT_NE(device->pipeline(shader, true), VK_NULL_HANDLE) << shader_name(shader) << " (fp16)";
    }
  }
  NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES();
}

}  // namespace
}  // namespace neuflow::model::vulkan
