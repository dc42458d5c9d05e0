#include "vulkan/shaders.hpp"

namespace neuflow::model::vulkan {

namespace {
// Each .spv.inc is glslc's C output (-mfmt=c): a braced list of SPIR-V words, generated from
// shaders/ by the build (model/CMakeLists.txt).
constexpr std::uint32_t kConv2d[] =
#include "conv2d.spv.inc"
    ;
constexpr std::uint32_t kMatmul[] =
#include "matmul.spv.inc"
    ;
constexpr std::uint32_t kAvgpool2x[] =
#include "avgpool2x.spv.inc"
    ;
constexpr std::uint32_t kResample[] =
#include "resample.spv.inc"
    ;
constexpr std::uint32_t kAxpby[] =
#include "axpby.spv.inc"
    ;
constexpr std::uint32_t kChannelAffine[] =
#include "channel_affine.spv.inc"
    ;
constexpr std::uint32_t kSoftmaxRows[] =
#include "softmax_rows.spv.inc"
    ;
constexpr std::uint32_t kLayerNorm[] =
#include "layer_norm.spv.inc"
    ;
constexpr std::uint32_t kLocalCorrelation[] =
#include "local_correlation.spv.inc"
    ;
constexpr std::uint32_t kRefineUpdate[] =
#include "refine_update.spv.inc"
    ;
constexpr std::uint32_t kConvexUpsample[] =
#include "convex_upsample.spv.inc"
    ;
}  // namespace

std::span<const std::uint32_t> spirv(Shader shader) {
  switch (shader) {
    case Shader::conv2d: return kConv2d;
    case Shader::matmul: return kMatmul;
    case Shader::avgpool2x: return kAvgpool2x;
    case Shader::resample: return kResample;
    case Shader::axpby: return kAxpby;
    case Shader::channel_affine: return kChannelAffine;
    case Shader::softmax_rows: return kSoftmaxRows;
    case Shader::layer_norm: return kLayerNorm;
    case Shader::local_correlation: return kLocalCorrelation;
    case Shader::refine_update: return kRefineUpdate;
    case Shader::convex_upsample: return kConvexUpsample;
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
  }
  return "?";
}

}  // namespace neuflow::model::vulkan
