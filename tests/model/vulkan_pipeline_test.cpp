// Every shader, in both precisions, makes a pipeline that the driver and the validation layer
// accept: a check of each SPIR-V module the build's shader compiler produced, without running
// the network (glslang 11, Ubuntu 22.04's glslangValidator, once produced an invalid fp16 one:
// a 16-bit constant without the Float16 capability).
#include <gtest/gtest.h>

#include <cstddef>

#include "support/vulkan.hpp"
#include "vulkan/shaders.hpp"
#include "vulkan/vulkan_device.hpp"

#include <chrono>
#include <cstdio>

namespace neuflow::model::vulkan {
namespace {

TEST(VulkanPipelines, EveryShaderInBothPrecisionsIsAcceptedByTheDriverAndTheValidationLayer) {
  NEUFLOW_REQUIRE_VULKAN();
  const auto device = VulkanDevice::open(0);
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    const auto shader = static_cast<Shader>(i);
    const auto t0 = std::chrono::steady_clock::now();
    EXPECT_NE(device->pipeline(shader, false), VK_NULL_HANDLE) << shader_name(shader);
    const auto t1 = std::chrono::steady_clock::now();
    if (device->info().fp16) {
      EXPECT_NE(device->pipeline(shader, true), VK_NULL_HANDLE) << shader_name(shader) << " (fp16)";
    }
    // What each pipeline costs the driver to create, once per process (lavapipe compiles then).
    std::printf("%-20s %7.1f ms, fp16 %7.1f ms\n", shader_name(shader),
                std::chrono::duration<double, std::milli>(t1 - t0).count(),
                std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t1).count());
  }
  NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES();
}

}  // namespace
}  // namespace neuflow::model::vulkan
