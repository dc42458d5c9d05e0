#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// out = a·x + b·y over `count` values (residuals, flow minus grid).
#include "common.glsl"
layout(std430, binding = 0) readonly buffer X { VALUE x[]; };
layout(std430, binding = 1) readonly buffer Y { VALUE y[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
#include "params/axpby_params.h"

void main() {
  FOR_EACH(i, p.count) dst[p.out_off + i] = VALUE(p.a * float(x[p.x_off + i]) + p.b * float(y[p.y_off + i]));
}
