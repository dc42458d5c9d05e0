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

#define READS_INPUT_TILES
#include "winograd_tile_io.glsl"

void main() {
  const int stride = p.c * p.tiles;  // between points
  FOR_EACH(i, p.c * p.tiles) {
    const int ci = i / p.tiles, t = i - ci * p.tiles;
    const int ty = t / p.tiles_x, tx = t - ty * p.tiles_x;
    float v[36];
    input_tile(ci, ty, tx, true, v);
    for (int k = 0; k < 36; ++k) points[k * stride + i] = v[k];
  }
}
