#pragma once
// How the Vulkan backend computes its stride-1 3×3 convolutions:
//  - winograd (the default): F(4×4, 3×3), a quarter of the multiply-adds. With the scalar
//    products it is one fused dispatch a layer (winograd_conv.comp: tiles transformed as they
//    are loaded, products transformed back as they are stored); with tensor-core products it
//    is split in three (input transform, the 36 products on the fragments, output transform);
//  - winograd-split: the three dispatches with the scalar products too (to compare them);
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
inline ConvAlgorithm conv_algorithm_for(ProductKernels products) {
  const char* v = std::getenv("NEUFLOW_VULKAN_CONV");
  const std::string want = v == nullptr ? "" : v;
  if (want.empty() || want == "winograd") {
    return products == ProductKernels::scalar ? ConvAlgorithm::winograd_fused : ConvAlgorithm::winograd_split;
  }
  if (want == "winograd-split") return ConvAlgorithm::winograd_split;
  if (want == "direct") return ConvAlgorithm::direct;
  throw std::invalid_argument("NEUFLOW_VULKAN_CONV: expected direct, winograd or winograd-split, got \"" + want + "\"");
}

}  // namespace neuflow::model::vulkan
