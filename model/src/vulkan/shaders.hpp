#pragma once
// The compute shaders, compiled to SPIR-V at build time (glslc) and embedded in the library.
#include <cstddef>
#include <cstdint>
#include <span>

namespace neuflow::model::vulkan {

enum class Shader {
  conv2d,          // matmul.comp with IMPLICIT_CONV
  matmul,          // matmul.comp, strided operands
  avgpool2x,
  resample,
  axpby,
  channel_affine,
  softmax_rows,
  layer_norm,
  local_correlation,
  refine_update,
  convex_upsample,
  frame_u8,        // a frame's 8-bit pixels as the network's input
};
inline constexpr std::size_t kShaderCount = 12;

// fp16: the variant that stores tensors as float16_t (precision.glsl).
std::span<const std::uint32_t> spirv(Shader shader, bool fp16);
const char* shader_name(Shader shader);

}  // namespace neuflow::model::vulkan
