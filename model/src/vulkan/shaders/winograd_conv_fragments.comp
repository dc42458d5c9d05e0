#version 450
#extension GL_GOOGLE_include_directive : require
// A stride-1 3×3 convolution by F(4×4, 3×3) in one dispatch with its 36 point products on
// 16×16 fragments (fp16 operands, fp32 sums): the tensor-core form of winograd_conv.comp. The
// split form (winograd_input, winograd_gemm on fragments, winograd_output) writes the
// transformed tiles and the products to memory in fp32 and reads them back: 3 dispatches and
// 4.5 fp32 bytes per input and per output value more. Here neither leaves the workgroup.
//
// A workgroup: 16 tiles × 16 output channels in 6 subgroups of 32. Subgroup i owns the 6
// points of row i of the 6×6 products (6 fragments of sums). Input channels in steps of 16:
// the step's 16 × 16 tiles are transformed as they are loaded (Bᵀ d B, each invocation a
// channel of a tile) into workgroup memory as fp16 [36][16 channels][16 tiles], the B operands;
// the A operands, the filters transformed at upload ([36][out][in] fp16, padded to 16), are
// loaded straight from their buffer. At the end each subgroup applies A to its row's 6 sums
// (6 points → 4, arithmetic on whole fragments), the rows meet in workgroup memory in two
// rounds of 2 columns, and Aᵀ, bias, addend and activation are applied as they are stored.
// Workgroup memory: 18 KiB of tiles and 12 KiB of rows, inside lavapipe's 32 KiB.
//  - TENSOR_CORES: VK_NV_cooperative_matrix fragments (GpuDevice::tensor_cores).
//  - otherwise the emulated twin, which any fp16 device (lavapipe included) runs: the same
//    operands in the same memory, each of a subgroup's 32 invocations holding 8 of a
//    fragment's 256 sums (rows lane / 16 + 2q, column lane % 16), each summed in fp32 from the
//    fp16 operands. The tests hold it to the CPU; the GPU check holds the real one to it.
#ifdef TENSOR_CORES
#extension GL_NV_cooperative_matrix : require
#extension GL_KHR_memory_scope_semantics : require
#extension GL_KHR_shader_subgroup_basic : require
#endif
#include "precision.glsl"
layout(local_size_x = 192) in;
layout(std430, binding = 0) readonly buffer Weights { VALUE u[]; };  // the bias
layout(std430, binding = 1) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer Addend { VALUE addend[]; };
layout(std430, binding = 4) readonly buffer Filters { float16_t filters[]; };
#ifdef INPUT_IN_PARTS
layout(std430, binding = 5) readonly buffer In2 { VALUE src2[]; };  // the input's second part
#endif
#ifdef STEP_CORRELATION
// The refinement step's end beside its conv3, as winograd_conv.comp's STEP_CORRELATION.
#ifdef STEP_UPDATE_ONLY
layout(std430, binding = 5) writeonly buffer Resampled { VALUE resampled[]; };
#else
layout(std430, binding = 5) readonly buffer F0 { VALUE f0[]; };
layout(std430, binding = 6) readonly buffer F1 { VALUE f1[]; };
#endif
layout(std430, binding = 7) buffer Flow { VALUE flow[]; };
#include "params/winograd_conv_step_params.h"
#else
#include "params/winograd_conv_params.h"
#endif
#include "activate.glsl"
#define READS_INPUT_TILES
#include "winograd_tile_io.glsl"

const int F = 16;  // a fragment: 16×16, K 16; the workgroup's tiles, channels and K step
shared float16_t points[36 * F * F];  // [point][channel][tile]: the B operands of a step
shared float rows[6 * 2 * F * F];     // [row i][column of the round][channel][tile]: m A

#ifdef TENSOR_CORES
#define OPERAND fcoopmatNV<16, gl_ScopeSubgroup, F, F>
#define SUMS fcoopmatNV<32, gl_ScopeSubgroup, F, F>
#else
// A fragment of sums as one invocation holds it: elements (lane / 16 + 2q, lane % 16).
struct Sums {
  float v[8];
};
#endif

// Output channel o0 + co, tile t0 + t, columns 2 · round + c of its 4×4 pixels, from the six
// rows' m A in `rows`: Aᵀ, then bias, addend and activation, as the direct convolution does.
void store_column(int co, int t, int round, int c) {
  if (co >= p.out_c || t >= p.tiles) return;
  float m[6];
  for (int i = 0; i < 6; ++i) m[i] = rows[((i * 2 + c) * F + co % F) * F + t % F];
  float o[4];
  output_1d(m[0], m[1], m[2], m[3], m[4], m[5], o);
  const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
  const int x = 4 * tx + 2 * round + c;
  if (x >= p.w) return;
  const float bias = p.bias_off >= 0 ? float(u[p.bias_off + co]) : 0.0;
  for (int r = 0; r < 4; ++r) {
    const int y = 4 * ty + r;
    if (y >= p.h) return;
    const int at = (co * p.h + y) * p.w + x;
    float v = o[r] + bias;
    if (p.add_off >= 0) v += float(addend[p.add_off + at]);
    dst[p.out_off + at] = VALUE(activate(v, p.act));
  }
}

// The workgroup of tiles group_t · 16 .. and output channels group_o · 16 ..
void convolve(int group_t, int group_o) {
  const int id = int(gl_LocalInvocationIndex);
  const int lane = id % 32;
#ifdef TENSOR_CORES
  const int row = int(gl_SubgroupID);  // the products' row this subgroup sums
#else
  const int row = id / 32;
#endif
  const int t0 = group_t * F, o0 = group_o * F;

#ifdef TENSOR_CORES
  SUMS acc[6];
  for (int j = 0; j < 6; ++j) acc[j] = SUMS(0.0);
#else
  Sums acc[6];
  for (int j = 0; j < 6; ++j)
    for (int q = 0; q < 8; ++q) acc[j].v[q] = 0.0;
#endif

  for (int c0 = 0; c0 < p.in_c; c0 += F) {
    for (int pair = id; pair < F * F; pair += 192) {
      const int k = pair / F, t = t0 + pair % F, ci = c0 + k;
      const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
      float v[36];
      input_tile(ci, ty, tx, ci < p.in_c && t < p.tiles, v);
      for (int i = 0; i < 36; ++i) points[i * F * F + pair] = float16_t(v[i]);
    }
    barrier();
    for (int j = 0; j < 6; ++j) {
      const int point = 6 * row + j;
      // Row o0 + r, column c0 + k of this point's filters.
      const int a = p.filters_off + (point * p.filters_out + o0) * p.filters_in + c0;
#ifdef TENSOR_CORES
      OPERAND fa, fb;
      coopMatLoadNV(fa, filters, a, p.filters_in, false);
      coopMatLoadNV(fb, points, point * F * F, F, false);
      acc[j] = coopMatMulAddNV(fa, fb, acc[j]);
#else
      for (int q = 0; q < 8; ++q) {
        const int r = lane / 16 + 2 * q, c = lane % 16;
        float s = acc[j].v[q];
        for (int k = 0; k < F; ++k) {
          s = fma(float(filters[a + r * p.filters_in + k]), float(points[(point * F + k) * F + c]), s);
        }
        acc[j].v[q] = s;
      }
#endif
    }
    barrier();
  }

  // m A along the row: 6 points → 4 columns, on whole fragments.
#ifdef TENSOR_CORES
  const SUMS sum12 = acc[1] + acc[2], diff12 = acc[1] - acc[2];
  const SUMS sum34 = acc[3] + acc[4], diff34 = acc[3] - acc[4];
  SUMS ma[4];
  ma[0] = acc[0] + sum12 + sum34;
  ma[1] = diff12 + 2.0 * diff34;
  ma[2] = sum12 + 4.0 * sum34;
  ma[3] = diff12 + 8.0 * diff34 + acc[5];
#else
  Sums ma[4];
  for (int q = 0; q < 8; ++q) {
    float o[4];
    output_1d(acc[0].v[q], acc[1].v[q], acc[2].v[q], acc[3].v[q], acc[4].v[q], acc[5].v[q], o);
    for (int c = 0; c < 4; ++c) ma[c].v[q] = o[c];
  }
#endif

  // The rows meet two columns at a time (all four would take 24 KiB).
  for (int round = 0; round < 2; ++round) {
    for (int c = 0; c < 2; ++c) {
      const int at = (row * 2 + c) * F * F;
#ifdef TENSOR_CORES
      coopMatStoreNV(ma[2 * round + c], rows, at, F, false);
#else
      for (int q = 0; q < 8; ++q) rows[at + (lane / 16 + 2 * q) * F + lane % 16] = ma[2 * round + c].v[q];
#endif
    }
    barrier();
    for (int e = id; e < 2 * F * F; e += 192) {
      const int c = e / (F * F), co = (e / F) % F, t = e % F;
      store_column(o0 + co, t0 + t, round, c);
    }
    barrier();
  }
}

#ifdef STEP_CORRELATION
#define CORRELATION_SCRATCH(i) rows[i]
#define CORRELATION_PIXELS kStepCorrelationPixels
#define STEP_DELTA
#include "local_correlation_block.glsl"
#include "step_correlation_main.glsl"
#else
void main() { convolve(int(gl_WorkGroupID.x), int(gl_WorkGroupID.y)); }
#endif
