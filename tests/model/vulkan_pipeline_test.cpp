// Every shader, in both precisions, makes a pipeline that the driver and the validation layer
// accept: a check of each SPIR-V module the build's shader compiler produced, without running
// the network (glslang 11, Ubuntu 22.04's glslangValidator, once produced an invalid fp16 one:
// a 16-bit constant without the Float16 capability). Those this device cannot run (the
// tensor-core shaders on lavapipe) are refused with an error, and every module, those
// included, passes spirv-val.
#include <gtest/gtest.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

#include "support/temp_dir.hpp"
#include "support/vulkan.hpp"
#include "vulkan/shaders.hpp"
#include "vulkan/vulkan_device.hpp"

namespace neuflow::model::vulkan {
namespace {

TEST(VulkanPipelines, EveryShaderInBothPrecisionsIsAcceptedByTheDriverAndTheValidationLayer) {
  NEUFLOW_REQUIRE_VULKAN();
  const auto device = VulkanDevice::open(0);
  int refused = 0;
  const auto create = [&](Shader shader, bool fp16) {
    const auto t0 = std::chrono::steady_clock::now();
    if (device->can_run(shader, fp16)) {
      EXPECT_NE(device->pipeline(shader, fp16), VK_NULL_HANDLE) << shader_name(shader) << (fp16 ? " (fp16)" : "");
    } else {
      EXPECT_THROW(device->pipeline(shader, fp16), BackendError) << shader_name(shader);
      ++refused;
    }
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  };
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    const auto shader = static_cast<Shader>(i);
    const double fp32_ms = create(shader, false), fp16_ms = create(shader, true);
    // What each pipeline costs the driver to create, once per process (lavapipe compiles then).
    std::printf("%-28s %7.1f ms, fp16 %7.1f ms\n", shader_name(shader), fp32_ms, fp16_ms);
  }
  std::printf("%d shader variants this device cannot run (fp16 only, or tensor cores)\n", refused);
  NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES();
}

// spirv-val (Debian's spirv-tools) on every module, the tensor-core ones too, which no device
// here runs: each must compile (with Debian 12's glslc or Ubuntu 22.04's glslangValidator) into
// SPIR-V that is valid for Vulkan 1.1.
TEST(VulkanPipelines, EveryShaderIsValidSpirv) {
  if (std::system("spirv-val --version > /dev/null 2>&1") != 0) {
    if (test::vulkan_required()) FAIL() << "spirv-val is not installed (apt install spirv-tools)";
    GTEST_SKIP() << "spirv-val is not installed (apt install spirv-tools)";
  }
  const test::TempDir dir("neuflow-spirv");
  int validated = 0;
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    const auto shader = static_cast<Shader>(i);
    for (const bool fp16 : {false, true}) {
      const auto words = spirv(shader, fp16);
      if (words.empty()) continue;
      const auto path = dir / (std::string(shader_name(shader)) + (fp16 ? "_fp16" : "") + ".spv");
      std::ofstream(path, std::ios::binary)
          .write(reinterpret_cast<const char*>(words.data()), static_cast<std::streamsize>(words.size_bytes()));
      const std::string command = "spirv-val --target-env vulkan1.1 '" + path.string() + "'";
      EXPECT_EQ(std::system(command.c_str()), 0) << command;
      ++validated;
    }
  }
  EXPECT_GE(validated, static_cast<int>(kShaderCount));
}

// The shaders that need tensor cores are compiled with TENSOR_CORES, and only they: their
// SPIR-V declares cooperative matrices (a CMake keyword among a shader's macros once dropped
// the macro, and every tensor-core shader was its twin). No device here runs them, so this is
// what holds the build to it.
TEST(VulkanPipelines, OnlyTheTensorCoreShadersUseCooperativeMatrices) {
  constexpr std::uint32_t kOpCapability = 17, kCapabilityCooperativeMatrixNV = 5357;
  int tensor_core_shaders = 0;
  for (std::size_t i = 0; i < kShaderCount; ++i) {
    const auto shader = static_cast<Shader>(i);
    const auto words = spirv(shader, true);
    bool cooperative = false;
    for (std::size_t at = 5; at < words.size();) {  // after the header, instruction by instruction
      const std::uint32_t count = words[at] >> 16, opcode = words[at] & 0xffffU;
      ASSERT_GT(count, 0U) << shader_name(shader);
      if (opcode == kOpCapability && words[at + 1] == kCapabilityCooperativeMatrixNV) cooperative = true;
      at += count;
    }
    EXPECT_EQ(cooperative, shader_info(shader).tensor_cores) << shader_name(shader);
    // ... and a shader named for tensor cores needs them (not only its twin is one)
    const std::string name = shader_name(shader);
    if (name.ends_with("_coopmat")) {
      EXPECT_TRUE(shader_info(shader).tensor_cores) << name;
    }
    tensor_core_shaders += shader_info(shader).tensor_cores ? 1 : 0;
  }
  EXPECT_GE(tensor_core_shaders, 6);
}

}  // namespace
}  // namespace neuflow::model::vulkan
