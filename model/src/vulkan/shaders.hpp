#pragma once
// The compute shaders, compiled to SPIR-V at build time and embedded in the library. Which
// shaders exist, their SPIR-V and their push-constant structs come from one list, the
// neuflow_shader() calls in model/CMakeLists.txt (cmake/NeuflowShaders.cmake generates
// shader_registry.hpp/.cpp from it).
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>

#include "vulkan/spirv_bindings.hpp"

namespace neuflow::model::vulkan {

// Every pipeline shares one push-constant range of this size (VulkanDevice's layout): the
// smallest maxPushConstantsSize Vulkan guarantees.
inline constexpr std::size_t kMaxPushConstantBytes = 128;
// Every shader's storage buffers are bindings 0 to 7 of one set layout (the refinement step's
// end beside its conv3 needs eight: the convolution's five and the correlation's features and
// flow; every GPU this runs on allows far more per stage than Vulkan's minimum of 4).
inline constexpr std::size_t kShaderBindings = 8;

struct ShaderInfo {
  const char* name;
  std::span<const std::uint32_t> spirv;       // empty for a shader that exists only in fp16
  std::span<const std::uint32_t> spirv_fp16;  // tensors stored as float16_t (precision.glsl)
  const char* params;                         // its push-constant struct (shaders/params/)
  std::size_t params_bytes;
  // What it does with each binding, from its SPIR-V: the recorder's barriers follow it.
  std::array<spirv_reflect::BindingAccess, kShaderBindings> bindings;
  // Needs VK_NV_cooperative_matrix (GpuDevice::tensor_cores): its pipelines exist only there.
  bool tensor_cores;
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
