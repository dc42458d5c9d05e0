#version 450
#extension GL_GOOGLE_include_directive : require
// LayerNorm over the channels of each token of a planar [dim][tokens] tensor (eps 1e-5),
// optionally added to a residual: out = residual + LN(x).
#include "common.glsl"
layout(std430, binding = 0) readonly buffer W { float w[]; };
layout(std430, binding = 1) readonly buffer X { float x[]; };
layout(std430, binding = 2) buffer Out { float dst[]; };
layout(std430, binding = 3) readonly buffer R { float res[]; };
layout(push_constant) uniform Params { int dim, tokens, x_off, out_off, res_off, gamma_off, beta_off; } p;

void main() {
  FOR_EACH(t, p.tokens) {
    float mean = 0.0;
    for (int c = 0; c < p.dim; ++c) mean += x[p.x_off + c * p.tokens + t];
    mean /= float(p.dim);
    float var = 0.0;
    for (int c = 0; c < p.dim; ++c) {
      const float d = x[p.x_off + c * p.tokens + t] - mean;
      var += d * d;
    }
    var /= float(p.dim);
    const float inv = inversesqrt(var + 1e-5);
    for (int c = 0; c < p.dim; ++c) {
      float v = (x[p.x_off + c * p.tokens + t] - mean) * inv * w[p.gamma_off + c] + w[p.beta_off + c];
      if (p.res_off >= 0) v += res[p.res_off + c * p.tokens + t];
      dst[p.out_off + c * p.tokens + t] = v;
    }
  }
}
