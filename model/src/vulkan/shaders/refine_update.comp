#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// The end of a refinement step: from conv3's output [delta 2, hidden 64], flow += delta, and
// the clamped hidden state and the new flow go into the next step's input
// [corr 81, hidden 64, flow 2]. With resampled_off >= 0 (a scale's last step), the new flow also
// goes, upsampled by `factor` (nearest) and scaled, into binding 1: the next scale's flow, or
// the upsampler's input, without a dispatch or copy of its own.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer Conv3 { VALUE o[]; };
layout(std430, binding = 1) writeonly buffer Resampled { VALUE resampled[]; };
layout(std430, binding = 2) buffer Input { VALUE input_data[]; };
layout(std430, binding = 3) buffer Flow { VALUE flow[]; };
#include "params/refine_update_params.h"

void main() {
  FOR_EACH(pix, p.plane) {
    for (int c = 0; c < 64; ++c) {
      input_data[p.hidden_off + c * p.plane + pix] = VALUE(clamp(float(o[(2 + c) * p.plane + pix]), -4.0, 4.0));
    }
    const int y = pix / p.w, x = pix - y * p.w, wide = p.w * p.factor, big = p.plane * p.factor * p.factor;
    for (int d = 0; d < 2; ++d) {
      const float v = float(flow[p.flow_off + d * p.plane + pix]) + float(o[d * p.plane + pix]);
      flow[p.flow_off + d * p.plane + pix] = VALUE(v);
      input_data[p.flow_in_off + d * p.plane + pix] = VALUE(v);
      if (p.resampled_off < 0) continue;
      for (int dy = 0; dy < p.factor; ++dy) {
        for (int dx = 0; dx < p.factor; ++dx) {
          resampled[p.resampled_off + d * big + (y * p.factor + dy) * wide + x * p.factor + dx] = VALUE(v * p.scale);
        }
      }
    }
  }
}
