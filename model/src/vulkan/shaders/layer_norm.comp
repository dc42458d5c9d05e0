#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// LayerNorm over the channels of each token of a planar [dim][tokens] tensor (eps 1e-5),
// optionally added to a residual: out = residual + LN(x), optionally followed by a folded
// BatchNorm (out · scale[c] + shift[c], the ChannelAffine op recorded into this dispatch; in
// fp16 that rounds once where the two dispatches rounded twice). A workgroup takes a block of 16
// tokens, 16 invocations per token each summing every 16th channel, the partial sums reduced in
// workgroup memory: 16 times the workgroups of one invocation per token (112 rather than 7 at
// 1792 tokens), with adjacent invocations still reading adjacent tokens. Two passes (mean, then
// variance about it), as the CPU computes it. With UNSTACKED (layer_norm_unstacked) both frames'
// tokens go to tensors of their own (p.split, unstacked_output.hpp).
layout(local_size_x = 16, local_size_y = 16) in;
layout(std430, binding = 0) readonly buffer W { VALUE w[]; };
layout(std430, binding = 1) readonly buffer X { VALUE x[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer R { VALUE res[]; };
#ifdef UNSTACKED
layout(std430, binding = 4) writeonly buffer Out2 { VALUE dst2[]; };
#endif
#include "params/layer_norm_params.h"

const int TOKENS = 16, LANES = 16;
shared float partial[LANES][TOKENS + 1];
shared float stat[TOKENS];

// The sum over the lanes of each token's partial sums, for every invocation of the token.
float reduce(float mine, int lane, int token) {
  partial[lane][token] = mine;
  barrier();
  if (lane == 0) {
    float s = 0.0;
    for (int l = 0; l < LANES; ++l) s += partial[l][token];
    stat[token] = s;
  }
  barrier();
  const float total = stat[token];
  barrier();  // stat and partial are written again by the next reduction
  return total;
}

void main() {
  const int token = int(gl_LocalInvocationID.x), lane = int(gl_LocalInvocationID.y);
  // Whole blocks loop together, so every invocation reaches every barrier.
  for (int block = int(gl_WorkGroupID.x) * TOKENS; block < p.tokens; block += int(gl_NumWorkGroups.x) * TOKENS) {
    const int t = block + token;
    const bool valid = t < p.tokens;
    float s = 0.0;
    if (valid) {
      for (int c = lane; c < p.dim; c += LANES) s += float(x[p.x_off + c * p.tokens + t]);
    }
    const float mean = reduce(s, lane, token) / float(p.dim);
    float v = 0.0;
    if (valid) {
      for (int c = lane; c < p.dim; c += LANES) {
        const float d = float(x[p.x_off + c * p.tokens + t]) - mean;
        v += d * d;
      }
    }
    const float inv = inversesqrt(reduce(v, lane, token) / float(p.dim) + 1e-5);
    if (!valid) continue;
    for (int c = lane; c < p.dim; c += LANES) {
      float o = (float(x[p.x_off + c * p.tokens + t]) - mean) * inv * float(w[p.gamma_off + c]) + float(w[p.beta_off + c]);
      if (p.res_off >= 0) o += float(res[p.res_off + c * p.tokens + t]);
      if (p.scale_off >= 0) o = o * float(w[p.scale_off + c]) + float(w[p.shift_off + c]);
#ifdef UNSTACKED
      if (t < p.split) {
        dst[p.out_off + c * p.split + t] = VALUE(o);
      } else {
        dst2[p.out2_off + c * p.split + t - p.split] = VALUE(o);
      }
#else
      dst[p.out_off + c * p.tokens + t] = VALUE(o);
#endif
    }
  }
}
