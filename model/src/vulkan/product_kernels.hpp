#pragma once
// Which kernels the Vulkan backend's products (the implicit-GEMM convolutions, the Winograd
// products and the matrix products) run on:
//  - scalar: matmul.comp, fp32 arithmetic, every device and precision;
//  - tensor_cores: matmul_fragments.comp on VK_NV_cooperative_matrix, fp16 operands and fp32
//    sums, where the device has them and the session stores fp16 (the default there);
//  - twin: the same tiles with the fragment products written out, which any fp16 device
//    runs: how lavapipe tests the tensor-core path's tiling and numbers.
// NEUFLOW_VULKAN_PRODUCTS=auto|scalar|tensor-cores|twin chooses (auto, the default: tensor
// cores where they run, else scalar).
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "neuflow/model/gpu_devices.hpp"
#include "vulkan/shaders.hpp"

namespace neuflow::model::vulkan {

enum class ProductKernels { scalar, tensor_cores, twin };

// Throws std::invalid_argument for a value it does not know, and BackendError (unavailable)
// where the device or the precision cannot run what the variable asks for.
inline ProductKernels product_kernels_for(const GpuDevice& device, bool fp16) {
  const char* v = std::getenv("NEUFLOW_VULKAN_PRODUCTS");
  const std::string want = v == nullptr || *v == '\0' ? "auto" : v;
  if (want == "auto") return fp16 && device.tensor_cores ? ProductKernels::tensor_cores : ProductKernels::scalar;
  if (want == "scalar") return ProductKernels::scalar;
  if (want != "tensor-cores" && want != "twin") {
    throw std::invalid_argument("NEUFLOW_VULKAN_PRODUCTS: expected auto, scalar, tensor-cores or twin, got \"" + want +
                                "\"");
  }
  if (!fp16) {
    throw BackendError(BackendError::Kind::unavailable,
                       "NEUFLOW_VULKAN_PRODUCTS=" + want + " multiplies fp16 operands: it needs precision fp16");
  }
  if (want == "tensor-cores" && !device.tensor_cores) {
    throw BackendError(BackendError::Kind::unavailable,
                       "NEUFLOW_VULKAN_PRODUCTS=tensor-cores: " + device.name +
                           " has no VK_NV_cooperative_matrix with 16×16×16 fp16 products in subgroups of 32 "
                           "(`neuflow devices` says which devices have tensor cores)");
  }
  return want == "twin" ? ProductKernels::twin : ProductKernels::tensor_cores;
}

// The shader that computes the product `scalar` (conv2d, matmul, matmul_norm, matmul_mlp_norm, winograd_gemm, the fused
// winograd_conv and its variants, or conv2d_convex) with `kernels`.
inline Shader product_shader(Shader scalar, ProductKernels kernels) {
  if (kernels == ProductKernels::scalar) return scalar;
  const bool cores = kernels == ProductKernels::tensor_cores;
  switch (scalar) {
    case Shader::conv2d: return cores ? Shader::conv2d_coopmat : Shader::conv2d_coopmat_twin;
    case Shader::conv2d_convex: return cores ? Shader::conv2d_convex_coopmat : Shader::conv2d_convex_coopmat_twin;
    case Shader::matmul: return cores ? Shader::matmul_coopmat : Shader::matmul_coopmat_twin;
    case Shader::matmul_norm: return cores ? Shader::matmul_norm_coopmat : Shader::matmul_norm_coopmat_twin;
    case Shader::matmul_mlp_norm: return cores ? Shader::matmul_mlp_norm_coopmat : Shader::matmul_mlp_norm_coopmat_twin;
    case Shader::winograd_gemm: return cores ? Shader::winograd_gemm_coopmat : Shader::winograd_gemm_coopmat_twin;
    case Shader::winograd_conv: return cores ? Shader::winograd_conv_coopmat : Shader::winograd_conv_coopmat_twin;
    case Shader::winograd_conv_parts:
      return cores ? Shader::winograd_conv_parts_coopmat : Shader::winograd_conv_parts_coopmat_twin;
    case Shader::winograd_conv_step:
      return cores ? Shader::winograd_conv_step_coopmat : Shader::winograd_conv_step_coopmat_twin;
    case Shader::winograd_conv_step_end:
      return cores ? Shader::winograd_conv_step_end_coopmat : Shader::winograd_conv_step_end_coopmat_twin;
    default: throw std::logic_error(std::string("product_shader: ") + shader_name(scalar) + " is not a product");
  }
}

// Whether a network whose products run on `kernels` records `shader`: every shader but the
// other kernels' products.
inline bool records(Shader shader, ProductKernels kernels) {
  for (const Shader scalar : {Shader::conv2d, Shader::matmul, Shader::matmul_norm, Shader::matmul_mlp_norm,
                              Shader::winograd_gemm, Shader::winograd_conv, Shader::winograd_conv_parts,
                              Shader::winograd_conv_step, Shader::winograd_conv_step_end, Shader::conv2d_convex}) {
    for (const ProductKernels k : {ProductKernels::scalar, ProductKernels::tensor_cores, ProductKernels::twin}) {
      if (product_shader(scalar, k) == shader) return k == kernels;
    }
  }
  return true;
}

}  // namespace neuflow::model::vulkan
