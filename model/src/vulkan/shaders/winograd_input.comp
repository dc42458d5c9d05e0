#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// F(4×4, 3×3)'s input transform: for each channel and 4×4 output tile, the 6×6 input tile
// around it (zeros outside the input: padding 1) as Bᵀ d B, one invocation per tile. The points
// stay fp32 in either precision: the transform multiplies values by up to 25.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Points { float points[]; };
#include "params/winograd_input_params.h"

#include "winograd_transforms.glsl"

void main() {
  const int plane = p.h * p.w;
  const int stride = p.c * p.tiles;  // between points
  FOR_EACH(i, p.c * p.tiles) {
    const int ci = i / p.tiles, t = i - ci * p.tiles;
    const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
    const int y0 = 4 * ty - 1, x0 = 4 * tx - 1;
    float d[6][6];
    for (int r = 0; r < 6; ++r) {
      const int y = y0 + r;
      for (int c = 0; c < 6; ++c) {
        const int x = x0 + c;
        d[r][c] = (y >= 0 && y < p.h && x >= 0 && x < p.w) ? float(src[p.in_off + ci * plane + y * p.w + x]) : 0.0;
      }
    }
    float cols[6][6];  // Bᵀ d: each column transformed
    for (int c = 0; c < 6; ++c) {
      float r[6];
      input_1d(d[0][c], d[1][c], d[2][c], d[3][c], d[4][c], d[5][c], r);
      for (int k = 0; k < 6; ++k) cols[k][c] = r[k];
    }
    for (int k = 0; k < 6; ++k) {  // (Bᵀ d) B: each row
      float r[6];
      input_1d(cols[k][0], cols[k][1], cols[k][2], cols[k][3], cols[k][4], cols[k][5], r);
      for (int j = 0; j < 6; ++j) points[(6 * k + j) * stride + i] = r[j];
    }
  }
}
