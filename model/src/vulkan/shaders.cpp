#include "vulkan/shaders.hpp"

namespace neuflow::model::vulkan {

namespace {
// Each .spv.inc is the shader compiler's list of SPIR-V words, comma-separated without braces
// (glslc -mfmt=num, glslangValidator -x), generated from shaders/ by the build (model/CMakeLists.txt).
constexpr std::uint32_t kConv2d[] = {
#include "conv2d.spv.inc"
};
constexpr std::uint32_t kMatmul[] = {
#include "matmul.spv.inc"
};
constexpr std::uint32_t kAvgpool2x[] = {
#include "avgpool2x.spv.inc"
};
constexpr std::uint32_t kResample[] = {
#include "resample.spv.inc"
};
constexpr std::uint32_t kAxpby[] = {
#include "axpby.spv.inc"
};
constexpr std::uint32_t kChannelAffine[] = {
#include "channel_affine.spv.inc"
};
constexpr std::uint32_t kSoftmaxRows[] = {
#include "softmax_rows.spv.inc"
};
constexpr std::uint32_t kLayerNorm[] = {
#include "layer_norm.spv.inc"
};
constexpr std::uint32_t kLocalCorrelation[] = {
#include "local_correlation.spv.inc"
};
constexpr std::uint32_t kRefineUpdate[] = {
#include "refine_update.spv.inc"
};
constexpr std::uint32_t kConvexUpsample[] = {
#include "convex_upsample.spv.inc"
};
constexpr std::uint32_t kFrameU8[] = {
#include "frame_u8.spv.inc"
};
constexpr std::uint32_t kConv2dFp16[] = {
#include "conv2d_fp16.spv.inc"
};
constexpr std::uint32_t kMatmulFp16[] = {
#include "matmul_fp16.spv.inc"
};
constexpr std::uint32_t kAvgpool2xFp16[] = {
#include "avgpool2x_fp16.spv.inc"
};
constexpr std::uint32_t kResampleFp16[] = {
#include "resample_fp16.spv.inc"
};
constexpr std::uint32_t kAxpbyFp16[] = {
#include "axpby_fp16.spv.inc"
};
constexpr std::uint32_t kChannelAffineFp16[] = {
#include "channel_affine_fp16.spv.inc"
};
constexpr std::uint32_t kSoftmaxRowsFp16[] = {
#include "softmax_rows_fp16.spv.inc"
};
constexpr std::uint32_t kLayerNormFp16[] = {
#include "layer_norm_fp16.spv.inc"
};
constexpr std::uint32_t kLocalCorrelationFp16[] = {
#include "local_correlation_fp16.spv.inc"
};
constexpr std::uint32_t kRefineUpdateFp16[] = {
#include "refine_update_fp16.spv.inc"
};
constexpr std::uint32_t kConvexUpsampleFp16[] = {
#include "convex_upsample_fp16.spv.inc"
};
constexpr std::uint32_t kFrameU8Fp16[] = {
#include "frame_u8_fp16.spv.inc"
};
}  // namespace

std::span<const std::uint32_t> spirv(Shader shader, bool fp16) {
  switch (shader) {
    case Shader::conv2d: return fp16 ? std::span<const std::uint32_t>(kConv2dFp16) : std::span<const std::uint32_t>(kConv2d);
    case Shader::matmul: return fp16 ? std::span<const std::uint32_t>(kMatmulFp16) : std::span<const std::uint32_t>(kMatmul);
    case Shader::avgpool2x: return fp16 ? std::span<const std::uint32_t>(kAvgpool2xFp16) : std::span<const std::uint32_t>(kAvgpool2x);
    case Shader::resample: return fp16 ? std::span<const std::uint32_t>(kResampleFp16) : std::span<const std::uint32_t>(kResample);
    case Shader::axpby: return fp16 ? std::span<const std::uint32_t>(kAxpbyFp16) : std::span<const std::uint32_t>(kAxpby);
    case Shader::channel_affine: return fp16 ? std::span<const std::uint32_t>(kChannelAffineFp16) : std::span<const std::uint32_t>(kChannelAffine);
    case Shader::softmax_rows: return fp16 ? std::span<const std::uint32_t>(kSoftmaxRowsFp16) : std::span<const std::uint32_t>(kSoftmaxRows);
    case Shader::layer_norm: return fp16 ? std::span<const std::uint32_t>(kLayerNormFp16) : std::span<const std::uint32_t>(kLayerNorm);
    case Shader::local_correlation: return fp16 ? std::span<const std::uint32_t>(kLocalCorrelationFp16) : std::span<const std::uint32_t>(kLocalCorrelation);
    case Shader::refine_update: return fp16 ? std::span<const std::uint32_t>(kRefineUpdateFp16) : std::span<const std::uint32_t>(kRefineUpdate);
    case Shader::convex_upsample: return fp16 ? std::span<const std::uint32_t>(kConvexUpsampleFp16) : std::span<const std::uint32_t>(kConvexUpsample);
    case Shader::frame_u8: return fp16 ? std::span<const std::uint32_t>(kFrameU8Fp16) : std::span<const std::uint32_t>(kFrameU8);
  }
  return {};
}

const char* shader_name(Shader shader) {
  switch (shader) {
    case Shader::conv2d: return "conv2d";
    case Shader::matmul: return "matmul";
    case Shader::avgpool2x: return "avgpool2x";
    case Shader::resample: return "resample";
    case Shader::axpby: return "axpby";
    case Shader::channel_affine: return "channel_affine";
    case Shader::softmax_rows: return "softmax_rows";
    case Shader::layer_norm: return "layer_norm";
    case Shader::local_correlation: return "local_correlation";
    case Shader::refine_update: return "refine_update";
    case Shader::convex_upsample: return "convex_upsample";
    case Shader::frame_u8: return "frame_u8";
  }
  return "?";
}

}  // namespace neuflow::model::vulkan
