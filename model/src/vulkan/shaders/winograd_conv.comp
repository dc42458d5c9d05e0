#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// A stride-1 3×3 convolution by F(4×4, 3×3) in one dispatch: the input tiles and the filters
// transformed as they are loaded into workgroup memory, the 36 point products summed in
// registers, transformed back with bias, addend and activation as they are stored. Neither the
// tiles nor the products go through global memory, where the split path (winograd_input,
// winograd_gemm, winograd_output) writes and reads again 4.5 fp32 bytes per input value and per
// output value; the filters are read as their 9 taps, not as 36 transformed points.
//
// A workgroup: 32 tiles × 16 output channels, in 192 invocations. The 36 points are 6 rows of
// the 6×6 products; an invocation sums one row (6 points) of 4 channels × 4 tiles, so each
// point's product is register-blocked 4×4 as a tiled GEMM is (8 loads a 16 multiply-adds), in
// 96 sums. Input channels in steps of 4: the step's transformed tiles (36 × 4 × 32) and filters
// (36 × 4 × 16) staged in 27 KiB of workgroup memory, inside the 32 KiB every desktop GPU,
// Jetson and lavapipe has. At the end each invocation applies A to its row (6 points → 4), and
// the rows meet in workgroup memory, in two rounds of 16 tiles, for Aᵀ.
layout(local_size_x = 192) in;
layout(std430, binding = 0) readonly buffer Weights { VALUE u[]; };
layout(std430, binding = 1) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer Addend { VALUE addend[]; };
#ifdef INPUT_IN_PARTS
layout(std430, binding = 5) readonly buffer In2 { VALUE src2[]; };  // the input's second part
#endif
#ifdef STEP_CORRELATION
// The refinement step's end beside its conv3, which computes only the hidden state (above: the
// output is the next step input's hidden channels, clamped): the workgroups from p.conv_groups
// on compute conv3's delta, the new flow and the next step's correlation
// (local_correlation_block.glsl with STEP_DELTA), which nothing the others write feeds.
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
#define WRITES_OUTPUT_TILES
#include "winograd_tile_io.glsl"

const int TILES = 32, CHANNELS = 16, STEP = 4;
const int FILTERS = 36 * STEP * TILES;  // where the staged filters start
// The staged tiles [36][STEP][TILES] and filters [36][STEP][CHANNELS]; at the end, the rows
// transformed by A: [CHANNELS][16 tiles][6 rows][4].
shared float staged[36 * STEP * (TILES + CHANNELS)];

// Transforms channel `ci` of tile `t` (zeros for tiles and channels past the last) into the
// staged tiles at step channel k, slot `slot`.
void stage_tile(int ci, int t, int k, int slot) {
  const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
  float v[36];
  input_tile(ci, ty, tx, ci < p.in_c && t < p.tiles, v);
  for (int i = 0; i < 36; ++i) staged[(i * STEP + k) * TILES + slot] = v[i];
}

// G g Gᵀ of the filter from step channel k (c0 + k) to output channel o (o0 + o), pair
// o + CHANNELS · k, into the staged filters (zeros for channels past the last).
void stage_filter(int o0, int c0, int pair) {
  const int o = pair % CHANNELS, k = pair / CHANNELS;
  const int co = o0 + o, ci = c0 + k;
  const bool inside = co < p.out_c && ci < p.in_c;
  const int base = p.w_off + (co * p.in_c + ci) * 9;
  float g[9];
  for (int t = 0; t < 9; ++t) g[t] = inside ? float(u[base + t]) : 0.0;
  float cols[6][3];  // G g
  for (int x = 0; x < 3; ++x) {
    float r[6];
    filter_1d(g[x], g[3 + x], g[6 + x], r);
    for (int i = 0; i < 6; ++i) cols[i][x] = r[i];
  }
  for (int i = 0; i < 6; ++i) {  // (G g) Gᵀ
    float r[6];
    filter_1d(cols[i][0], cols[i][1], cols[i][2], r);
    for (int j = 0; j < 6; ++j) staged[FILTERS + ((6 * i + j) * STEP + k) * CHANNELS + o] = r[j];
  }
}

// Output channel `co`, tile `t`, from its 6 rows transformed by A (at `at` in staged).
void store_tile(int co, int t, int at) {
  if (co >= p.out_c || t >= p.tiles) return;
  float rows[6][4];
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 4; ++j) rows[i][j] = staged[at + 4 * i + j];
  store_output_tile(co, t / p.tiles_x, t % p.tiles_x, rows, p.bias_off >= 0 ? float(u[p.bias_off + co]) : 0.0);
}

// The workgroup of tiles group_t · 32 .. and output channels group_o · 16 ..
void convolve(int group_t, int group_o) {
  const int id = int(gl_LocalInvocationIndex);
  const int row = id / 32, position = id % 32;
  const int cg = position / 8, tg = position % 8;  // channels o0 + cg + 4a, tiles t0 + tg + 8b
  const int t0 = group_t * TILES, o0 = group_o * CHANNELS;
  float m[6][4][4];  // points 6·row + j, channel a, tile b
  for (int j = 0; j < 6; ++j)
    for (int a = 0; a < 4; ++a)
      for (int b = 0; b < 4; ++b) m[j][a][b] = 0.0;

  for (int c0 = 0; c0 < p.in_c; c0 += STEP) {
    if (id < STEP * TILES) stage_tile(c0 + id / TILES, t0 + id % TILES, id / TILES, id % TILES);
    if (id >= 192 - STEP * CHANNELS) stage_filter(o0, c0, id - (192 - STEP * CHANNELS));
    barrier();
    for (int j = 0; j < 6; ++j) {
      const int point = 6 * row + j;
      for (int k = 0; k < STEP; ++k) {
        float f[4], t[4];
        for (int a = 0; a < 4; ++a) f[a] = staged[FILTERS + (point * STEP + k) * CHANNELS + cg + 4 * a];
        for (int b = 0; b < 4; ++b) t[b] = staged[(point * STEP + k) * TILES + tg + 8 * b];
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) m[j][a][b] = fma(f[a], t[b], m[j][a][b]);
      }
    }
    barrier();
  }

  // Two rounds: tiles tg + 8b for b in {0, 1}, then {2, 3} (16 tiles each).
  for (int round = 0; round < 2; ++round) {
    for (int a = 0; a < 4; ++a) {
      for (int bb = 0; bb < 2; ++bb) {
        const int b = 2 * round + bb;
        float o[4];  // this row of the products times A
        output_1d(m[0][a][b], m[1][a][b], m[2][a][b], m[3][a][b], m[4][a][b], m[5][a][b], o);
        const int pair = (cg + 4 * a) * 16 + tg + 8 * bb;
        for (int q = 0; q < 4; ++q) staged[(pair * 6 + row) * 4 + q] = o[q];
      }
    }
    barrier();
    for (int pair = id; pair < CHANNELS * 16; pair += 192) {
      const int o = pair / 16, slot = pair % 16;
      store_tile(o0 + o, t0 + 16 * round + slot, pair * 24);
    }
    barrier();
  }
}

#ifdef STEP_CORRELATION
#define CORRELATION_SCRATCH(i) staged[i]
#define CORRELATION_PIXELS kStepCorrelationPixels
#define STEP_DELTA
#include "local_correlation_block.glsl"
#include "step_correlation_main.glsl"
#else
void main() { convolve(int(gl_WorkGroupID.x), int(gl_WorkGroupID.y)); }
#endif
