#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Channels of a planar tensor copied into a channel range of another, nearest-neighbour
// upsampled by `factor` (1: a plain copy), optionally through ReLU, then scaled.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
#include "params/resample_params.h"

void main() {
  const int oh = p.in_h * p.factor, ow = p.in_w * p.factor;
  FOR_EACH(i, p.channels * oh * ow) {
    const int c = i / (oh * ow), r = i - c * oh * ow;
    const int y = r / ow, x = r - y * ow;
    float v = float(src[p.in_off + c * p.in_h * p.in_w + (y / p.factor) * p.in_w + x / p.factor]);
    if (p.relu != 0) v = max(v, 0.0);
    dst[p.out_off + i] = VALUE(v * p.scale);
  }
}
