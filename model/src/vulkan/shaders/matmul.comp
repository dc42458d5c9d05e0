#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// C = act(alpha · A · B + bias + addend) in fp32 scalar arithmetic, tiled through workgroup
// memory: 16×16 invocations, each TM×TN outputs (specialization constants, so each tile size is
// its own pipeline with the loops unrolled: 128×128 tiles of 8×8 where the grid stays wide,
// 64×64 of 4×4 or 32×32 of 2×2 where it would leave a large GPU idle; gemm_tile.hpp chooses),
// K in steps of 16, the next step's operands loaded into registers while the current step's
// are multiplied. Every output's products are summed in the same order at every tile size, so
// the sizes agree to the bit. Compiled for the three kinds of product of gemm_operands.glsl
// (IMPLICIT_CONV, WINOGRAD_GEMM, strided), the strided one also with a LayerNorm of each column
// as its epilogue (LAYER_NORM, layer_norm_tile.glsl: 192×16 tiles). Every device runs it;
// matmul_fragments.comp is the tensor-core path of the same products.
layout(local_size_x = 16, local_size_y = 16) in;
// A LayerNorm epilogue's tile, 192×16, is also the defaults: the validation layer sizes
// workgroup memory by them.
#ifdef LAYER_NORM
layout(constant_id = 0) const int TM = 12;
layout(constant_id = 1) const int TN = 1;
#else
layout(constant_id = 0) const int TM = 4;  // outputs per invocation along M (rows of C)
layout(constant_id = 1) const int TN = 4;  // and along N (columns of C): 1, 2, 4, 8 or 16
#endif

layout(std430, binding = 0) readonly buffer BufA { VALUE a_data[]; };
#ifdef WINOGRAD_GEMM
layout(std430, binding = 1) readonly buffer BufB { float b_data[]; };
layout(std430, binding = 2) writeonly buffer BufC { float c_data[]; };
#elif defined(CONVEX_UPSAMPLE)
layout(std430, binding = 1) readonly buffer BufB { VALUE b_data[]; };
layout(std430, binding = 2) writeonly buffer BufC { float c_data[]; };  // the flow for the host
#elif defined(LAYER_NORM)
layout(std430, binding = 1) readonly buffer BufB { VALUE b_data[]; };
layout(std430, binding = 2) writeonly buffer BufC { VALUE c_data[]; };
layout(std430, binding = 4) writeonly buffer BufC2 { VALUE out2[]; };  // frame 1's tokens, unstacked
#else
layout(std430, binding = 1) readonly buffer BufB { VALUE b_data[]; };
layout(std430, binding = 2) buffer BufC { VALUE c_data[]; };
#endif
layout(std430, binding = 3) readonly buffer BufD { VALUE d_data[]; };  // the addend (the 1/8 flow), or the residual

#ifdef IMPLICIT_CONV
#include "params/conv2d_params.h"
#elif defined(WINOGRAD_GEMM)
#include "params/winograd_gemm_params.h"
#elif defined(LAYER_NORM)
#include "params/matmul_norm_params.h"
#else
#include "params/matmul_params.h"
#endif

#include "gemm_operands.glsl"

// The staged operands in the type they are stored in: fp16 tensors stay fp16 in workgroup
// memory (exactly: they are widened to fp32 as they are multiplied, as before), which halves it
// (8 KiB for a 128×128 tile) and so leaves room for more workgroups at once. The split Winograd's
// transformed tiles are fp32 in either precision, so its products stage fp32.
#if defined(FP16) && !defined(WINOGRAD_GEMM)
#define STAGED float16_t
const int PAD = 2;
#else
#define STAGED float
const int PAD = 1;
#endif

const int BM = 16 * TM, BN = 16 * TN, BK = 16;
#ifdef MLP
const int PASSES = kMlpHiddenChannels / BM + 1;  // the hidden layer's row blocks, then the second product
#else
const int PASSES = 1;
#endif
// tile_a's rows padded by one 32-bit word: the 16 invocations that store a column's 16 k values
// (adjacent in the weights) then write 16 different banks, where a row of 32, 64 or 128 values
// put them in one or two.
shared STAGED tile_a[BK][BM + PAD];
shared STAGED tile_b[BK][BN];
#ifdef CONVEX_UPSAMPLE
#include "convex_upsample_tile.glsl"
#endif
#ifdef LAYER_NORM
#include "layer_norm_tile.glsl"
#endif

void main() {
  const int tx = int(gl_LocalInvocationID.x), ty = int(gl_LocalInvocationID.y);
  const int tid = ty * 16 + tx;
  const int col0 = int(gl_WorkGroupID.x) * BN;  // columns of C (output pixels)
  for (int pass = 0; pass < PASSES; ++pass) {
#ifdef MLP
    mlp_phase = pass + 1 < PASSES ? 0 : 1;
    barrier();  // the hidden layer whole before the second product reads it
    const int row0 = mlp_phase == 0 ? pass * BM : 0;  // a block of the hidden layer's rows, or all C's
#else
    const int row0 = int(gl_WorkGroupID.y) * BM;  // rows of C (output channels)
#endif
    const int K = gemm_k();
    // B: each invocation gathers one column (fixed across the K loop) at TN consecutive k of each
    // step (256 / BN invocations a column, TN k each: the step's 16), followed by a cursor, so no
    // gathered element divides.
    const GemmColumn column = gemm_column(col0 + tid % BN);
    const int b_row = TN * (tid / BN);
    GemmCursor b_at = gemm_cursor(b_row);
    const GemmCursor one = gemm_cursor(1), step = gemm_cursor(BK);

    float acc[TM][TN];
    for (int i = 0; i < TM; ++i)
      for (int j = 0; j < TN; ++j) acc[i][j] = 0.0;

    // The next step's operands wait in registers while this step's are multiplied (a GPU hides
    // the global loads' latency behind the arithmetic that way), then go to workgroup memory.
    float next_a[TM], next_b[TN];
    for (int r = 0; r < TM; ++r) {
      const int e = tid + 256 * r;  // A: BM rows × 16 k, adjacent invocations adjacent k
      next_a[r] = gemm_a(row0 + e / BK, e % BK);
    }
    GemmCursor c = b_at;
    for (int r = 0; r < TN; ++r) {
      next_b[r] = gemm_b(column, c);
      gemm_advance(c, one);
    }

    for (int k0 = 0; k0 < K; k0 += BK) {
      for (int r = 0; r < TM; ++r) {
        const int e = tid + 256 * r;
        tile_a[e % BK][e / BK] = STAGED(next_a[r]);
      }
      for (int r = 0; r < TN; ++r) tile_b[b_row + r][tid % BN] = STAGED(next_b[r]);
      barrier();
      if (k0 + BK < K) {
        for (int r = 0; r < TM; ++r) {
          const int e = tid + 256 * r;
          next_a[r] = gemm_a(row0 + e / BK, k0 + BK + e % BK);
        }
        gemm_advance(b_at, step);
        c = b_at;
        for (int r = 0; r < TN; ++r) {
          next_b[r] = gemm_b(column, c);
          gemm_advance(c, one);
        }
      }
      for (int kk = 0; kk < BK; ++kk) {
        float av[TM], bv[TN];
        for (int i = 0; i < TM; ++i) av[i] = float(tile_a[kk][ty + 16 * i]);
        for (int j = 0; j < TN; ++j) bv[j] = float(tile_b[kk][tx + 16 * j]);
        for (int i = 0; i < TM; ++i)
          for (int j = 0; j < TN; ++j) acc[i][j] = fma(av[i], bv[j], acc[i][j]);
      }
      barrier();
    }

#ifdef CONVEX_UPSAMPLE
    for (convex_half = 0; convex_half < 2; ++convex_half) {
      for (int i = 0; i < TM; ++i)
        for (int j = 0; j < TN; ++j) convex_store(row0 + ty + 16 * i, col0 + tx + 16 * j, acc[i][j]);
      barrier();
      convex_upsample_tile(tid, 256);
      barrier();
    }
#else
    for (int i = 0; i < TM; ++i)
      for (int j = 0; j < TN; ++j) PRODUCT_STORE(row0 + ty + 16 * i, col0 + tx + 16 * j, acc[i][j]);
#endif
  }
#ifdef LAYER_NORM
  layer_norm_tile(tid, 256);
#endif
}
