#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// In place on a planar tensor: x[c][i] = x[c][i] · scale[c] + shift[c] (a folded BatchNorm).
#include "common.glsl"
layout(std430, binding = 0) readonly buffer W { VALUE w[]; };
layout(std430, binding = 2) buffer X { VALUE x[]; };
#include "params/channel_affine_params.h"

void main() {
  FOR_EACH(i, p.channels * p.plane) {
    const int c = i / p.plane;
    x[p.x_off + i] = VALUE(float(x[p.x_off + i]) * float(w[p.scale_off + c]) + float(w[p.shift_off + c]));
  }
}
