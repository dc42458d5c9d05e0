#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Convex upsampling ×8: output pixel (8y + a, 8x + b) = 8 · Σ_k softmax_k(mask[k·64 + a·8 + b])
// · flow8[3×3 neighbour k of (y, x)], zero outside. Planar mask [576][h8·w8], flow8 [2][h8·w8].
// The flow leaves as the host hands it on: interleaved [8h8][8w8][2] fp32, into the ring entry's
// read-back buffer, whatever the tensors' precision (nothing converts it on the host). An
// observed pass also gets it planar [2][8h8][8w8] in the tensors' precision, the stage's tensor.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer Mask { VALUE mask[]; };
layout(std430, binding = 1) readonly buffer Flow8 { VALUE flow8[]; };
layout(std430, binding = 2) writeonly buffer FlowOut { float flow_out[]; };
layout(std430, binding = 3) writeonly buffer Planar { VALUE planar[]; };
#include "params/convex_upsample_params.h"
#define CONVEX_FLOW8(i) float(flow8[i])
#include "convex_combination.glsl"

void main() {
  const int plane8 = p.h8 * p.w8;
  const int W = p.w8 * 8, H = p.h8 * 8;
  FOR_EACH(i, H * W) {
    const int Y = i / W, X = i - Y * W;
    const int y = Y / 8, a = Y % 8, x = X / 8, b = X % 8;
    float logit[9];
    for (int k = 0; k < 9; ++k) logit[k] = float(mask[(k * 64 + a * 8 + b) * plane8 + y * p.w8 + x]);
    const vec2 f = convex_flow(logit, y, x, p.h8, p.w8);
    flow_out[2 * i] = f.x;
    flow_out[2 * i + 1] = f.y;
    if (p.planar != 0) {
      planar[i] = VALUE(f.x);
      planar[H * W + i] = VALUE(f.y);
    }
  }
}
