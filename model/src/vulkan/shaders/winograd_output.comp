#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// F(4×4, 3×3)'s output transform: for each output channel and 4×4 tile, Aᵀ m A of its 36
// products, then bias, addend and activation, as the direct convolution applies them.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer W { VALUE w[]; };
layout(std430, binding = 1) readonly buffer Products { float m[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer Addend { VALUE addend[]; };
#include "params/winograd_output_params.h"
#include "activate.glsl"

#define WRITES_OUTPUT_TILES
#include "winograd_tile_io.glsl"

void main() {
  const int stride = p.c * p.tiles;  // between points
  FOR_EACH(i, p.c * p.tiles) {
    const int co = i / p.tiles, t = i - co * p.tiles;
    const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
    float rows[6][4];  // m A: each row of the 6×6 products transformed
    for (int k = 0; k < 6; ++k) {
      float o[4];
      output_1d(m[(6 * k) * stride + i], m[(6 * k + 1) * stride + i], m[(6 * k + 2) * stride + i],
                m[(6 * k + 3) * stride + i], m[(6 * k + 4) * stride + i], m[(6 * k + 5) * stride + i], o);
      for (int j = 0; j < 4; ++j) rows[k][j] = o[j];
    }
    store_output_tile(co, ty, tx, rows, p.bias_off >= 0 ? float(w[p.bias_off + co]) : 0.0);
  }
}
