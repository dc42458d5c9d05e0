#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// LayerNorm over the channels of each token of a planar [dim][tokens] tensor (eps 1e-5),
// optionally added to a residual: out = residual + LN(x).
#include "common.glsl"
layout(std430, binding = 0) readonly buffer W { VALUE w[]; };
layout(std430, binding = 1) readonly buffer X { VALUE x[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer R { VALUE res[]; };
#include "params/layer_norm_params.h"

void main() {
  FOR_EACH(t, p.tokens) {
    float mean = 0.0;
    for (int c = 0; c < p.dim; ++c) mean += float(x[p.x_off + c * p.tokens + t]);
    mean /= float(p.dim);
    float var = 0.0;
    for (int c = 0; c < p.dim; ++c) {
      const float d = float(x[p.x_off + c * p.tokens + t]) - mean;
      var += d * d;
    }
    var /= float(p.dim);
    const float inv = inversesqrt(var + 1e-5);
    for (int c = 0; c < p.dim; ++c) {
      float v = (float(x[p.x_off + c * p.tokens + t]) - mean) * inv * float(w[p.gamma_off + c]) + float(w[p.beta_off + c]);
      if (p.res_off >= 0) v += float(res[p.res_off + c * p.tokens + t]);
      dst[p.out_off + c * p.tokens + t] = VALUE(v);
    }
  }
}
