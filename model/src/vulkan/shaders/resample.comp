#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Channels of a planar tensor copied into a channel range of another, nearest-neighbour
// upsampled by `factor` (1: a plain copy), optionally through ReLU, then scaled. With a second
// source (binding 1, channels2 > 0), its channels follow the first's in the output: both parts
// of a concatenation in one dispatch.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
layout(std430, binding = 1) readonly buffer In2 { VALUE src2[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
#include "params/resample_params.h"

void main() {
  const int oh = p.in_h * p.factor, ow = p.in_w * p.factor, plane = oh * ow;
  FOR_EACH(i, (p.channels + p.channels2) * plane) {
    const int c = i / plane, r = i - c * plane;
    const int y = r / ow, x = r - y * ow;
    float v;
    if (c < p.channels) {
      v = float(src[p.in_off + c * p.in_h * p.in_w + (y / p.factor) * p.in_w + x / p.factor]);
      if (p.relu != 0) v = max(v, 0.0);
      v *= p.scale;
    } else {
      const int c2 = c - p.channels;
      v = float(src2[p.in2_off + c2 * p.in2_h * p.in2_w + (y / p.factor2) * p.in2_w + x / p.factor2]);
      if (p.relu2 != 0) v = max(v, 0.0);
      v *= p.scale2;
    }
    dst[p.out_off + i] = VALUE(v);
  }
}
