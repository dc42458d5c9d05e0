#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Three 2×2 average poolings of a planar [C][H][W] tensor in one pass (H and W multiples of 8):
// each invocation reads an 8×8 block and writes its 4×4 of the half-size tensor, 2×2 of the
// quarter and 1 of the eighth, each level from the one above as stored (rounded to VALUE), so
// the results are avgpool2x.comp's three dispatches' exactly.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
layout(std430, binding = 2) writeonly buffer Half { VALUE half_size[]; };
layout(std430, binding = 3) writeonly buffer Quarter { VALUE quarter[]; };
layout(std430, binding = 4) writeonly buffer Eighth { VALUE eighth[]; };
#include "params/avgpool_pyramid_params.h"

void main() {
  const int h8 = p.in_h / 8, w8 = p.in_w / 8, h2 = p.in_h / 2, w2 = p.in_w / 2, h4 = p.in_h / 4, w4 = p.in_w / 4;
  FOR_EACH(i, p.channels * h8 * w8) {
    const int c = i / (h8 * w8), r = i - c * h8 * w8;
    const int y = r / w8, x = r - y * w8;
    float level2[4][4];
    for (int dy = 0; dy < 4; ++dy) {
      for (int dx = 0; dx < 4; ++dx) {
        const int base = c * p.in_h * p.in_w + (8 * y + 2 * dy) * p.in_w + 8 * x + 2 * dx;
        const VALUE v = VALUE((float(src[base]) + float(src[base + 1]) + float(src[base + p.in_w]) +
                               float(src[base + p.in_w + 1])) * 0.25);
        half_size[c * h2 * w2 + (4 * y + dy) * w2 + 4 * x + dx] = v;
        level2[dy][dx] = float(v);
      }
    }
    float level4[2][2];
    for (int dy = 0; dy < 2; ++dy) {
      for (int dx = 0; dx < 2; ++dx) {
        const VALUE v = VALUE((level2[2 * dy][2 * dx] + level2[2 * dy][2 * dx + 1] + level2[2 * dy + 1][2 * dx] +
                               level2[2 * dy + 1][2 * dx + 1]) * 0.25);
        quarter[c * h4 * w4 + (2 * y + dy) * w4 + 2 * x + dx] = v;
        level4[dy][dx] = float(v);
      }
    }
    eighth[i] = VALUE((level4[0][0] + level4[0][1] + level4[1][0] + level4[1][1]) * 0.25);
  }
}
