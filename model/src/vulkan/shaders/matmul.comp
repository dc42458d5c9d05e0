#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// C = act(alpha · A · B + bias + addend) in fp32 scalar arithmetic, tiled through workgroup
// memory: 64×64 outputs per workgroup, 4×4 per invocation, K in steps of 16, the next step's
// operands loaded into registers while the current step's are multiplied. Compiled for
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
// tile_a's rows padded by one: the 16 invocations that store a column's 16 k values (adjacent
// in the weights) then write 16 different banks, where a 64-float row put them all in one.
shared float tile_a[BK][BM + 1];
shared float tile_b[BK][BN];

void main() {
  const int tx = int(gl_LocalInvocationID.x), ty = int(gl_LocalInvocationID.y);
  const int tid = ty * 16 + tx;
  const int row0 = int(gl_WorkGroupID.y) * BM;  // rows of C (output channels)
  const int col0 = int(gl_WorkGroupID.x) * BN;  // columns of C (output pixels)
  const int K = gemm_k();
  // B: each invocation gathers one column (fixed across the K loop) at 4 consecutive k of each
  // step, followed by a cursor, so no gathered element divides.
  const GemmColumn column = gemm_column(col0 + tid % BN);
  const int b_row = 4 * (tid / BN);
  GemmCursor b_at = gemm_cursor(b_row);
  const GemmCursor one = gemm_cursor(1), step = gemm_cursor(BK);

  float acc[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) acc[i][j] = 0.0;

  // The next step's operands wait in registers while this step's are multiplied (a GPU hides
  // the global loads' latency behind the arithmetic that way), then go to workgroup memory.
  float next_a[4], next_b[4];
  for (int r = 0; r < 4; ++r) {
    const int e = tid + 256 * r;  // A: 64 rows × 16 k, adjacent invocations adjacent k
    next_a[r] = gemm_a(row0 + e / BK, e % BK);
  }
  GemmCursor c = b_at;
  for (int r = 0; r < 4; ++r) {
    next_b[r] = gemm_b(column, c);
    gemm_advance(c, one);
  }

  for (int k0 = 0; k0 < K; k0 += BK) {
    for (int r = 0; r < 4; ++r) {
      const int e = tid + 256 * r;
      tile_a[e % BK][e / BK] = next_a[r];
      tile_b[b_row + r][tid % BN] = next_b[r];
    }
    barrier();
    if (k0 + BK < K) {
      for (int r = 0; r < 4; ++r) {
        const int e = tid + 256 * r;
        next_a[r] = gemm_a(row0 + e / BK, k0 + BK + e % BK);
      }
      gemm_advance(b_at, step);
      c = b_at;
      for (int r = 0; r < 4; ++r) {
        next_b[r] = gemm_b(column, c);
        gemm_advance(c, one);
      }
    }
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
