// winograd_gemm (matmul.comp with WINOGRAD_GEMM): for each of the 36 points (workgroup z),
// products[z] = filters[z] · points[z]: [out_c][in_c] by [in_c][tiles], the filters (binding 0,
// at w_off) in the tensors' type, the points (binding 1) and the products (binding 2) fp32.
// The filters are laid out [36][filters_out][filters_in], out_c and in_c rounded up to 16
// (DeviceWeights), as the fused tensor-core convolution loads them.
#ifndef NEUFLOW_SHADER_WINOGRAD_GEMM_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_GEMM_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(WinogradGemmParams)
  int m, n, k;  // out_c, tiles, in_c
  int w_off;
  int filters_in, filters_out;
NEUFLOW_PUSH_CONSTANTS_END

#endif
