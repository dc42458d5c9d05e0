#pragma once
// The compute shaders, compiled to SPIR-V at build time and embedded in the library. Which
// shaders exist, their SPIR-V and their push-constant structs come from one list, the
// neuflow_shader() calls in model/CMakeLists.txt (cmake/NeuflowShaders.cmake generates
// shader_registry.hpp/.cpp from it).
#include <cstddef>
#include <cstdint>
#include <span>

namespace neuflow::model::vulkan {

// Every pipeline shares one push-constant range of this size (VulkanDevice's layout): the
// smallest maxPushConstantsSize Vulkan guarantees.
inline constexpr std::size_t kMaxPushConstantBytes = 128;

struct ShaderInfo {
  const char* name;
  std::span<const std::uint32_t> spirv;
  std::span<const std::uint32_t> spirv_fp16;  // tensors stored as float16_t (precision.glsl)
  const char* params;                         // its push-constant struct (shaders/params/)
  std::size_t params_bytes;
};

}  // namespace neuflow::model::vulkan

#include "shader_registry.hpp"  // Shader, kShaderCount, ShaderParams<Shader>

namespace neuflow::model::vulkan {

const ShaderInfo& shader_info(Shader shader);

inline std::span<const std::uint32_t> spirv(Shader shader, bool fp16) {
  return fp16 ? shader_info(shader).spirv_fp16 : shader_info(shader).spirv;
}
inline const char* shader_name(Shader shader) { return shader_info(shader).name; }

}  // namespace neuflow::model::vulkan
