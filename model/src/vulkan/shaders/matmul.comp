#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// C = act(alpha · A · B + bias + addend) in fp32 scalar arithmetic, tiled through workgroup
// memory: 64×64 outputs per workgroup, 4×4 per invocation, K in steps of 16. Compiled for
// the three kinds of product of gemm_operands.glsl (IMPLICIT_CONV, WINOGRAD_GEMM, strided).
// Every device runs it; matmul_fragments.comp is the tensor-core path of the same products.
layout(local_size_x = 16, local_size_y = 16) in;

layout(std430, binding = 0) readonly buffer BufA { VALUE a_data[]; };
#ifdef WINOGRAD_GEMM
layout(std430, binding = 1) readonly buffer BufB { float b_data[]; };
layout(std430, binding = 2) writeonly buffer BufC { float c_data[]; };
#else
layout(std430, binding = 1) readonly buffer BufB { VALUE b_data[]; };
layout(std430, binding = 2) buffer BufC { VALUE c_data[]; };
#endif
layout(std430, binding = 3) readonly buffer BufD { VALUE d_data[]; };  // the addend

#ifdef IMPLICIT_CONV
#include "params/conv2d_params.h"
#elif defined(WINOGRAD_GEMM)
#include "params/winograd_gemm_params.h"
#else
#include "params/matmul_params.h"
#endif

#include "gemm_operands.glsl"

const int BM = 64, BN = 64, BK = 16;
shared float tile_a[BK][BM];
shared float tile_b[BK][BN];

void main() {
  const int tx = int(gl_LocalInvocationID.x), ty = int(gl_LocalInvocationID.y);
  const int tid = ty * 16 + tx;
  const int row0 = int(gl_WorkGroupID.y) * BM;  // rows of C (output channels)
  const int col0 = int(gl_WorkGroupID.x) * BN;  // columns of C (output pixels)
  const int K = gemm_k();
  // The column this invocation gathers for B: fixed across the K loop (256 % 64 == 0).
  const GemmColumn column = gemm_column(col0 + (tid % BN));

  float acc[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) acc[i][j] = 0.0;

  for (int k0 = 0; k0 < K; k0 += BK) {
    // A tile: 64 rows × 16 k, adjacent invocations read adjacent k (row-major weights).
    for (int r = 0; r < 4; ++r) {
      const int e = tid + 256 * r;
      const int kk = e % BK, mm = e / BK;
      tile_a[kk][mm] = gemm_a(row0 + mm, k0 + kk);
    }
    // B tile: 16 k × 64 columns, adjacent invocations read adjacent columns.
    for (int r = 0; r < 4; ++r) {
      const int kk = tid / BN + 4 * r;
      tile_b[kk][tid % BN] = gemm_b(column, k0 + kk);
    }
    barrier();
    for (int kk = 0; kk < BK; ++kk) {
      float av[4], bv[4];
      for (int i = 0; i < 4; ++i) av[i] = tile_a[kk][ty + 16 * i];
      for (int j = 0; j < 4; ++j) bv[j] = tile_b[kk][tx + 16 * j];
      for (int i = 0; i < 4; ++i)
        for (int j = 0; j < 4; ++j) acc[i][j] = fma(av[i], bv[j], acc[i][j]);
    }
    barrier();
  }

  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) gemm_store(row0 + ty + 16 * i, col0 + tx + 16 * j, acc[i][j]);
}
