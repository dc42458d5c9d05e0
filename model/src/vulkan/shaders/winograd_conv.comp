#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// A stride-1 3×3 convolution by F(4×4, 3×3) in one dispatch: the input tiles transformed as they
// are loaded into workgroup memory, the 36 point products summed in registers, transformed back
// with bias, addend and activation as they are stored. Neither the tiles nor the products go
// through global memory, which the split path (winograd_input, winograd_gemm, winograd_output)
// spends 4.5 fp32 bytes per input value and per output value on, each written and read again.
//
// A workgroup: 32 tiles × 16 output channels; an invocation: 2 tiles × 1 channel, 72 sums.
// Input channels in steps of 4, each step's transformed tiles (36 × 4 × 32) and filters
// (36 × 16 × 4) staged in fp32 workgroup memory: 27 KiB, inside the 32 KiB every desktop GPU,
// Jetson and lavapipe has.
layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, binding = 0) readonly buffer Filters { VALUE u[]; };
layout(std430, binding = 1) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer Addend { VALUE addend[]; };
#include "params/winograd_conv_params.h"
#include "activate.glsl"
#include "winograd_transforms.glsl"

const int TILES = 32, CHANNELS = 16, STEP = 4;
shared float points[36][STEP][TILES];     // Bᵀ d B of each staged channel and tile
shared float filters[36][CHANNELS][STEP];  // G g Gᵀ of each (output, input) channel pair

// Transforms channel `ci` of tile `t` (zeros past the input, and for tiles and channels past
// the last) into points[·][k][slot].
void stage_tile(int ci, int t, int k, int slot) {
  float d[6][6];
  const bool inside = ci < p.in_c && t < p.tiles;
  const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
  const int y0 = 4 * ty - 1, x0 = 4 * tx - 1;
  const int base = p.in_off + ci * p.h * p.w;
  for (int r = 0; r < 6; ++r) {
    const int y = y0 + r;
    for (int c = 0; c < 6; ++c) {
      const int x = x0 + c;
      d[r][c] = (inside && y >= 0 && y < p.h && x >= 0 && x < p.w) ? float(src[base + y * p.w + x]) : 0.0;
    }
  }
  float cols[6][6];  // Bᵀ d
  for (int c = 0; c < 6; ++c) {
    float r[6];
    input_1d(d[0][c], d[1][c], d[2][c], d[3][c], d[4][c], d[5][c], r);
    for (int i = 0; i < 6; ++i) cols[i][c] = r[i];
  }
  for (int i = 0; i < 6; ++i) {  // (Bᵀ d) B
    float r[6];
    input_1d(cols[i][0], cols[i][1], cols[i][2], cols[i][3], cols[i][4], cols[i][5], r);
    for (int j = 0; j < 6; ++j) points[6 * i + j][k][slot] = r[j];
  }
}

// Aᵀ m A of tile `t`'s 36 sums for output channel `co`, then bias, addend, activation.
void store_tile(int co, int t, float m[36]) {
  if (co >= p.out_c || t >= p.tiles) return;
  const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
  float rows[6][4];  // m A
  for (int i = 0; i < 6; ++i) {
    float o[4];
    output_1d(m[6 * i], m[6 * i + 1], m[6 * i + 2], m[6 * i + 3], m[6 * i + 4], m[6 * i + 5], o);
    for (int j = 0; j < 4; ++j) rows[i][j] = o[j];
  }
  const float bias = p.bias_off >= 0 ? float(u[p.bias_off + co]) : 0.0;
  const int plane = p.h * p.w;
  for (int j = 0; j < 4; ++j) {  // Aᵀ (m A)
    float o[4];
    output_1d(rows[0][j], rows[1][j], rows[2][j], rows[3][j], rows[4][j], rows[5][j], o);
    const int x = 4 * tx + j;
    if (x >= p.w) continue;
    for (int r = 0; r < 4; ++r) {
      const int y = 4 * ty + r;
      if (y >= p.h) continue;
      const int at = co * plane + y * p.w + x;
      float v = o[r] + bias;
      if (p.add_off >= 0) v += float(addend[p.add_off + at]);
      dst[p.out_off + at] = VALUE(activate(v, p.act));
    }
  }
}

void main() {
  const int lx = int(gl_LocalInvocationID.x), ly = int(gl_LocalInvocationID.y);
  const int id = ly * 16 + lx;
  const int t0 = int(gl_WorkGroupID.x) * TILES, o0 = int(gl_WorkGroupID.y) * CHANNELS;
  float m0[36], m1[36];  // the sums of tiles t0 + lx and t0 + lx + 16, output channel o0 + ly
  for (int i = 0; i < 36; ++i) {
    m0[i] = 0.0;
    m1[i] = 0.0;
  }
  for (int c0 = 0; c0 < p.in_c; c0 += STEP) {
    if (id < STEP * TILES) stage_tile(c0 + id / TILES, t0 + id % TILES, id / TILES, id % TILES);
    for (int e = id; e < 36 * CHANNELS * STEP; e += 256) {  // adjacent invocations, adjacent input channels
      const int k = e % STEP, o = (e / STEP) % CHANNELS, point = e / (STEP * CHANNELS);
      const int co = o0 + o, ci = c0 + k;
      filters[point][o][k] =
          co < p.out_c && ci < p.in_c ? float(u[p.filters_off + (point * p.out_c + co) * p.in_c + ci]) : 0.0;
    }
    barrier();
    for (int i = 0; i < 36; ++i) {
      for (int k = 0; k < STEP; ++k) {
        const float f = filters[i][ly][k];
        m0[i] = fma(f, points[i][k][lx], m0[i]);
        m1[i] = fma(f, points[i][k][lx + 16], m1[i]);
      }
    }
    barrier();
  }
  store_tile(o0 + ly, t0 + lx, m0);
  store_tile(o0 + ly, t0 + lx + 16, m1);
}
