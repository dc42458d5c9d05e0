#pragma once
// How the Vulkan backend computes its stride-1 3×3 convolutions:
//  - winograd (the default): F(4×4, 3×3), a quarter of the multiply-adds, in one fused dispatch
//    a layer: tiles transformed as they are loaded, products transformed back as they are
//    stored. With the scalar products, winograd_conv.comp (the filters transformed as they are
//    loaded too); with tensor-core products, winograd_conv_fragments.comp (the filters
//    transformed at upload, loaded as fragments);
//  - winograd-split: in three dispatches (input transform, the 36 products, output transform),
//    the tiles and products through memory: to compare;
//  - direct: the implicit GEMM every other convolution takes (to compare, and as a way back
//    should a driver miscompile the Winograd shaders).
// NEUFLOW_VULKAN_CONV=direct|winograd|winograd-split chooses.
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "vulkan/product_kernels.hpp"

namespace neuflow::model::vulkan {

enum class ConvAlgorithm { direct, winograd_fused, winograd_split };

// std::invalid_argument naming the variable when it holds anything else.
inline ConvAlgorithm conv_algorithm_for() {
  const char* v = std::getenv("NEUFLOW_VULKAN_CONV");
  const std::string want = v == nullptr ? "" : v;
  if (want.empty() || want == "winograd") return ConvAlgorithm::winograd_fused;
  if (want == "winograd-split") return ConvAlgorithm::winograd_split;
  if (want == "direct") return ConvAlgorithm::direct;
  throw std::invalid_argument("NEUFLOW_VULKAN_CONV: expected direct, winograd or winograd-split, got \"" + want + "\"");
}

// Whether the Winograd filters are transformed when the weights are uploaded: wherever the
// products run apart from the filter transform (all but the scalar fused shader, which
// transforms them as it loads them).
inline bool winograd_filters_at_upload(ConvAlgorithm conv, ProductKernels products) {
  return conv == ConvAlgorithm::winograd_split ||
         (conv == ConvAlgorithm::winograd_fused && products != ProductKernels::scalar);
}

}  // namespace neuflow::model::vulkan
