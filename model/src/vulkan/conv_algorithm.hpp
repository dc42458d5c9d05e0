#pragma once
// How the Vulkan backend computes its stride-1 3×3 convolutions: Winograd F(4×4, 3×3) (the
// default: a quarter of the multiply-adds), or the direct implicit GEMM every other
// convolution takes. NEUFLOW_VULKAN_CONV=direct|winograd chooses (to compare them, and as a
// way back should a driver miscompile the Winograd shaders).
#include <cstdlib>
#include <stdexcept>
#include <string>

namespace neuflow::model::vulkan {

// std::invalid_argument naming the variable when it holds anything else.
inline bool winograd_from_environment() {
  const char* v = std::getenv("NEUFLOW_VULKAN_CONV");
  if (v == nullptr || *v == '\0' || std::string(v) == "winograd") return true;
  if (std::string(v) == "direct") return false;
  throw std::invalid_argument(std::string("NEUFLOW_VULKAN_CONV: expected direct or winograd, got \"") + v + "\"");
}

}  // namespace neuflow::model::vulkan
