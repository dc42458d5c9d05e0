#version 450
#extension GL_GOOGLE_include_directive : require
// The products of gemm_operands.glsl on tensor cores: fp16 operands, fp32 sums. A workgroup
// computes a BM×BN tile of C in subgroups of 32, each subgroup FM×FN fragments of 16×16, over K
// in steps of 32 (two fragment steps of 16) staged as fp16 through workgroup memory. The tile
// comes from specialization constants as the scalar kernel's does (gemm_tile.hpp):
//  - 64×64: 4 subgroups (2×2), each 2×2 fragments (the shader's own, without specialization);
//  - 128×128: 8 subgroups (4×2), each 2×4 fragments, 256 invocations;
//  - 32×32: 4 subgroups (2×2), each one fragment;
//  - with LAYER_NORM (a LayerNorm of each column as the epilogue, layer_norm_tile.glsl): 192×16,
//    4 subgroups down the rows, each 3×1 fragments.
// Each output's fragment products are summed in K order at every size.
//  - TENSOR_CORES: the fragments are VK_NV_cooperative_matrix matrices (16×16×16,
//    fp16 × fp16 + fp32), taken where the device has them (GpuDevice::tensor_cores).
//  - otherwise the emulated twin, which any fp16 device (lavapipe included) runs: the same
//    tiles, the same fp16 operands in the same workgroup memory, the same staging of the sums
//    and the same epilogue; only the 16×16×16 product is written out, each of a subgroup's 32
//    invocations summing 8 of a fragment's 256 outputs in fp32. The tests check the twin
//    against the CPU at every product the network has, and the GPU check the real thing
//    against the twin.
#ifdef TENSOR_CORES
#extension GL_NV_cooperative_matrix : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#endif
#include "precision.glsl"
// 32 × the subgroups: 128 (the default), or 256 for 128×128. The workgroup size and the
// constant the code reads are two specialization constants set alike: a driver may read
// gl_WorkGroupSize at run time (lavapipe does, and then nothing sized by it unrolls).
layout(local_size_x = 128, local_size_x_id = 3) in;
// A LayerNorm epilogue's tile, 192×16, is also the defaults: the validation layer sizes
// workgroup memory by them.
#ifdef LAYER_NORM
layout(constant_id = 0) const int TM = 12;
layout(constant_id = 1) const int TN = 1;
#else
layout(constant_id = 0) const int TM = 4;  // the tile: BM = 16·TM rows of C
layout(constant_id = 1) const int TN = 4;  // and BN = 16·TN columns
#endif
layout(constant_id = 2) const int INVOCATIONS = 128;

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

// The workgroup's tile and K step: 32, but 16 where a LayerNorm epilogue needs workgroup memory.
#ifdef LAYER_NORM
const int BM = 16 * TM, BN = 16 * TN, BK = 16;
#else
const int BM = 16 * TM, BN = 16 * TN, BK = 32;
#endif
#ifdef MLP
const int PASSES = kMlpHiddenChannels / BM + 1;  // the hidden layer's row blocks, then the second product
#else
const int PASSES = 1;
#endif
const int F = 16;                               // a fragment: 16×16, K 16
// With LAYER_NORM the tile is every row of 16 columns (192×16, 4 subgroups down its rows).
#ifdef LAYER_NORM
const int WARPS_N = 1;
#else
const int WARPS_N = 2;
#endif
const int WARPS = INVOCATIONS / 32, WARPS_M = WARPS / WARPS_N;
// A subgroup's fragments. The twin's arrays are sized by them, not by the largest tile's: an
// array larger than its use stays in memory on lavapipe (the 64×64 twin took 2× the time). The
// cooperative matrices' arrays keep a fixed size, the largest tile's (a form drivers have long
// compiled), of which a smaller tile uses part.
const int FM = BM / (F * WARPS_M), FN = BN / (F * WARPS_N);
#ifdef LAYER_NORM
const int MAX_FM = 3, MAX_FN = 1;
#else
const int MAX_FM = 2, MAX_FN = 4;
#endif
// Row strides in workgroup memory, padded by 16 bytes: a fragment load's rows start on 16-byte
// boundaries (as cooperative-matrix loads need) in different banks.
const int SA = BK + 8, SB = BN + 8, SC = F + 4;
shared float16_t tile_a[BM * SA];  // [m][k]
shared float16_t tile_b[BK * SB];  // [k][n]
shared float sums[WARPS * F * SC];  // one fragment's sums per subgroup, on their way out
#ifdef CONVEX_UPSAMPLE
#include "convex_upsample_tile.glsl"
#endif
#ifdef LAYER_NORM
#include "layer_norm_tile.glsl"
#endif

#ifdef TENSOR_CORES
#define OPERAND fcoopmatNV<16, gl_ScopeSubgroup, F, F>
#define SUMS fcoopmatNV<32, gl_ScopeSubgroup, F, F>
#endif

void main() {
  const int tid = int(gl_LocalInvocationIndex);
  const int lane = tid % 32;
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
    // B is gathered by column, each invocation the same column through the K loop, at B_RUN
    // consecutive k of each step, followed by a cursor (no gathered element divides).
    const int A_LOADS = BM * BK / INVOCATIONS, B_RUN = BK * BN / INVOCATIONS;
    const GemmColumn column = gemm_column(col0 + tid % BN);
    const int b_row = B_RUN * (tid / BN);
    GemmCursor b_at = gemm_cursor(b_row);
    const GemmCursor one = gemm_cursor(1), step = gemm_cursor(BK);
#ifdef TENSOR_CORES
    const int warp = int(gl_SubgroupID);
#else
    const int warp = tid / 32;
#endif
    const int warp_row = (warp / WARPS_N) * F * FM, warp_col = (warp % WARPS_N) * F * FN;  // its part of the tile

#ifdef TENSOR_CORES
    SUMS acc[MAX_FM][MAX_FN];
    for (int i = 0; i < FM; ++i)
      for (int j = 0; j < FN; ++j) acc[i][j] = SUMS(0.0);
#else
    // Invocation `lane` holds rows lane / 16 + 2q, column lane % 16 of each fragment.
    float acc[FM][FN][8];
    for (int i = 0; i < FM; ++i)
      for (int j = 0; j < FN; ++j)
        for (int q = 0; q < 8; ++q) acc[i][j][q] = 0.0;
#endif

    for (int k0 = 0; k0 < K; k0 += BK) {
      // A: BM rows × 32 k, adjacent invocations read adjacent k (row-major weights).
      for (int r = 0; r < A_LOADS; ++r) {
        const int e = tid + INVOCATIONS * r;
        const int kk = e % BK, mm = e / BK;
        tile_a[mm * SA + kk] = float16_t(gemm_a(row0 + mm, k0 + kk));
      }
      // B: 32 k × BN columns, adjacent invocations read adjacent columns.
      GemmCursor c = b_at;
      for (int r = 0; r < B_RUN; ++r) {
        tile_b[(b_row + r) * SB + tid % BN] = float16_t(gemm_b(column, c));
        gemm_advance(c, one);
      }
      gemm_advance(b_at, step);
      barrier();
      for (int kf = 0; kf < BK; kf += F) {
#ifdef TENSOR_CORES
        OPERAND a[MAX_FM], b[MAX_FN];
        for (int i = 0; i < FM; ++i) coopMatLoadNV(a[i], tile_a, (warp_row + F * i) * SA + kf, SA, false);
        for (int j = 0; j < FN; ++j) coopMatLoadNV(b[j], tile_b, kf * SB + warp_col + F * j, SB, false);
        for (int i = 0; i < FM; ++i)
          for (int j = 0; j < FN; ++j) acc[i][j] = coopMatMulAddNV(a[i], b[j], acc[i][j]);
#else
        for (int i = 0; i < FM; ++i)
          for (int j = 0; j < FN; ++j)
            for (int q = 0; q < 8; ++q) {
              const int a_row = (warp_row + F * i + lane / 16 + 2 * q) * SA + kf;
              const int b_col = kf * SB + warp_col + F * j + lane % 16;
              float s = acc[i][j][q];
              for (int t = 0; t < F; ++t) s = fma(float(tile_a[a_row + t]), float(tile_b[b_col + t * SB]), s);
              acc[i][j][q] = s;
            }
#endif
      }
      barrier();
    }

    // The sums leave a fragment at a time through workgroup memory, so that the epilogue knows
    // where each is (a cooperative matrix's layout across invocations is the driver's).
#ifdef CONVEX_UPSAMPLE
    for (convex_half = 0; convex_half < 2; ++convex_half) {
#endif
    const int out_row = ((tid / 32) / WARPS_N) * F * FM, out_col = ((tid / 32) % WARPS_N) * F * FN;
    for (int i = 0; i < FM; ++i)
      for (int j = 0; j < FN; ++j) {
#ifdef TENSOR_CORES
        coopMatStoreNV(acc[i][j], sums, warp * F * SC, SC, false);
#else
        for (int q = 0; q < 8; ++q) sums[warp * F * SC + (lane / 16 + 2 * q) * SC + lane % 16] = acc[i][j][q];
#endif
        barrier();
        for (int q = 0; q < 8; ++q) {
          const int r = lane / 16 + 2 * q, c = lane % 16;
          PRODUCT_STORE(row0 + out_row + F * i + r, col0 + out_col + F * j + c, sums[(tid / 32) * F * SC + r * SC + c]);
        }
        barrier();
      }
#ifdef CONVEX_UPSAMPLE
      convex_upsample_tile(tid, INVOCATIONS);
      barrier();
    }
#endif
  }
#ifdef LAYER_NORM
  layer_norm_tile(tid, INVOCATIONS);
#endif
}
