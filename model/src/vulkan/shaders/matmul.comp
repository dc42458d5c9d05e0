#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// C = act(alpha · A · B + bias + addend), tiled through workgroup memory: 64×64 outputs per
// workgroup, 4×4 per invocation, K in steps of 16. Compiled twice:
//  - IMPLICIT_CONV: A is a convolution's OIHW weights read as a row-major [Cout][Cin·k·k]
//    matrix and B the im2col of a planar [C][H][W] input, gathered on the fly (never stored);
//    C is the planar output. Bias and activation fused; `addend` (same shape as C) is added
//    before the activation.
//  - WINOGRAD_GEMM: the 36 products of F(4×4, 3×3), one per workgroup z: the transformed
//    filters [36][Cout][Cin] (binding 0) by the transformed input tiles [36][Cin][tiles] into
//    [36][Cout][tiles]; the tiles and products are fp32 in either precision.
//  - otherwise a general strided product (attention, matching): every operand has a row and a
//    column stride, so transposes are free.
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

const int BM = 64, BN = 64, BK = 16;
shared float tile_a[BK][BM];
shared float tile_b[BK][BN];

#include "activate.glsl"

void main() {
  const int tx = int(gl_LocalInvocationID.x), ty = int(gl_LocalInvocationID.y);
  const int tid = ty * 16 + tx;
  const int row0 = int(gl_WorkGroupID.y) * BM;  // rows of C (output channels)
  const int col0 = int(gl_WorkGroupID.x) * BN;  // columns of C (output pixels)
#ifdef IMPLICIT_CONV
  const int M = p.out_c, N = p.out_h * p.out_w, K = p.in_c * p.kernel * p.kernel;
  const int kk2 = p.kernel * p.kernel;
  const int in_plane = p.in_h * p.in_w;
  // The column this invocation gathers for B: fixed across the K loop (256 % 64 == 0).
  const int my_col = col0 + (tid % BN);
  const int oy = my_col / p.out_w, ox = my_col % p.out_w;
  const int iy0 = oy * p.stride - p.pad, ix0 = ox * p.stride - p.pad;
  const bool col_ok = my_col < N;
#else
  const int M = p.m, N = p.n, K = p.k;
#endif
#ifdef WINOGRAD_GEMM
  const int point = int(gl_WorkGroupID.z);
  const int a_base = p.w_off + point * M * K, b_base = point * K * N, c_base = point * M * N;
#endif

  float acc[4][4];
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) acc[i][j] = 0.0;

  for (int k0 = 0; k0 < K; k0 += BK) {
    // A tile: 64 rows × 16 k, adjacent invocations read adjacent k (row-major weights).
    for (int r = 0; r < 4; ++r) {
      const int e = tid + 256 * r;
      const int kk = e % BK, mm = e / BK;
      const int gm = row0 + mm, gk = k0 + kk;
      float v = 0.0;
      if (gm < M && gk < K) {
#if defined(IMPLICIT_CONV)
        v = float(a_data[p.w_off + gm * K + gk]);
#elif defined(WINOGRAD_GEMM)
        v = float(a_data[a_base + gm * K + gk]);
#else
        v = float(a_data[p.a_off + gm * p.a_rs + gk * p.a_cs]);
#endif
      }
      tile_a[kk][mm] = v;
    }
    // B tile: 16 k × 64 columns, adjacent invocations read adjacent columns.
    for (int r = 0; r < 4; ++r) {
      const int e = tid + 256 * r;
      const int nn = e % BN, kk = e / BN;
      const int gk = k0 + kk;
      float v = 0.0;
#ifdef IMPLICIT_CONV
      if (col_ok && gk < K) {
        const int ci = gk / kk2, rem = gk - ci * kk2;
        const int ky = rem / p.kernel, kx = rem - ky * p.kernel;
        const int iy = iy0 + ky, ix = ix0 + kx;
        if (iy >= 0 && iy < p.in_h && ix >= 0 && ix < p.in_w) {
          v = float(b_data[p.in_off + ci * in_plane + iy * p.in_w + ix]);
        }
      }
#elif defined(WINOGRAD_GEMM)
      const int gn = col0 + nn;
      if (gn < N && gk < K) v = b_data[b_base + gk * N + gn];
#else
      const int gn = col0 + nn;
      if (gn < N && gk < K) v = float(b_data[p.b_off + gk * p.b_rs + gn * p.b_cs]);
#endif
      tile_b[kk][nn] = v;
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

  for (int i = 0; i < 4; ++i) {
    const int gm = row0 + ty + 16 * i;
    if (gm >= M) continue;
#ifdef IMPLICIT_CONV
    const float bias = p.bias_off >= 0 ? float(a_data[p.bias_off + gm]) : 0.0;
    for (int j = 0; j < 4; ++j) {
      const int gn = col0 + tx + 16 * j;
      if (gn >= N) continue;
      float v = p.alpha * acc[i][j] + bias;
      if (p.add_off >= 0) v += float(d_data[p.add_off + gm * N + gn]);
      c_data[p.out_off + gm * N + gn] = VALUE(activate(v, p.act));
    }
#elif defined(WINOGRAD_GEMM)
    for (int j = 0; j < 4; ++j) {
      const int gn = col0 + tx + 16 * j;
      if (gn < N) c_data[c_base + gm * N + gn] = acc[i][j];
    }
#else
    const float bias = p.bias_off >= 0 ? float(a_data[p.bias_off + gm]) : 0.0;
    for (int j = 0; j < 4; ++j) {
      const int gn = col0 + tx + 16 * j;
      if (gn >= N) continue;
      c_data[p.c_off + gm * p.c_rs + gn * p.c_cs] = VALUE(activate(p.alpha * acc[i][j] + bias, p.act));
    }
#endif
  }
}
