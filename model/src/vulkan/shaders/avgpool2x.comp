#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// 2×2 average pooling of a planar [C][H][W] tensor.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
#include "params/avgpool2x_params.h"

void main() {
  const int oh = p.in_h / 2, ow = p.in_w / 2;
  FOR_EACH(i, p.channels * oh * ow) {
    const int c = i / (oh * ow), r = i - c * oh * ow;
    const int y = r / ow, x = r - y * ow;
    const int base = c * p.in_h * p.in_w + 2 * y * p.in_w + 2 * x;
    dst[i] = VALUE((float(src[base]) + float(src[base + 1]) + float(src[base + p.in_w]) + float(src[base + p.in_w + 1])) * 0.25);
  }
}
