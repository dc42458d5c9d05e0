#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// Three 2×2 average poolings of a planar [C][H][W] tensor in one pass (H and W multiples of 8):
// each invocation reads an 8×8 block and writes its 4×4 of the half-size tensor, 2×2 of the
// quarter and 1 of the eighth, each level from the one above as stored (rounded to VALUE), so
// the results are avgpool2x.comp's three dispatches' exactly.
// With FROM_FRAME_U8 the block comes from the frame's 8-bit pixels as frame_u8.comp converts
// them (edge-padded, channels swapped for BGR), and is written as the network's input too: the
// frame's input and its pyramid in one dispatch.
#include "common.glsl"
#ifdef FROM_FRAME_U8
layout(std430, binding = 0) readonly buffer In { uint words[]; };
layout(std430, binding = 1) writeonly buffer Input { VALUE input_data[]; };
#else
layout(std430, binding = 0) readonly buffer In { VALUE src[]; };
#endif
layout(std430, binding = 2) writeonly buffer Half { VALUE half_size[]; };
layout(std430, binding = 3) writeonly buffer Quarter { VALUE quarter[]; };
layout(std430, binding = 4) writeonly buffer Eighth { VALUE eighth[]; };
#include "params/avgpool_pyramid_params.h"

#ifdef FROM_FRAME_U8
uint byte_at(int i) { return (words[i >> 2] >> (8 * (i & 3))) & 0xffu; }
#endif

// The input's value at (c, y, x), as stored.
float source(int c, int y, int x) {
  const int at = (c * p.in_h + y) * p.in_w + x;
#ifdef FROM_FRAME_U8
  const int sx = clamp(x - p.pad_left, 0, p.frame_w - 1), sy = clamp(y - p.pad_top, 0, p.frame_h - 1);
  const int from = p.swap != 0 ? 2 - c : c;
  const VALUE v = VALUE(float(byte_at(3 * (sy * p.frame_w + sx) + from)) * (1.0 / 255.0));
  input_data[at] = v;
  return float(v);
#else
  return float(src[at]);
#endif
}

void main() {
  const int h8 = p.in_h / 8, w8 = p.in_w / 8, h2 = p.in_h / 2, w2 = p.in_w / 2, h4 = p.in_h / 4, w4 = p.in_w / 4;
  FOR_EACH(i, p.channels * h8 * w8) {
    const int c = i / (h8 * w8), r = i - c * h8 * w8;
    const int y = r / w8, x = r - y * w8;
    float level2[4][4];
    for (int dy = 0; dy < 4; ++dy) {
      for (int dx = 0; dx < 4; ++dx) {
        const int sy = 8 * y + 2 * dy, sx = 8 * x + 2 * dx;
        // In avgpool2x.comp's order of summation.
        const float a = source(c, sy, sx), b = source(c, sy, sx + 1), d = source(c, sy + 1, sx),
                    e = source(c, sy + 1, sx + 1);
        const VALUE v = VALUE((a + b + d + e) * 0.25);
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
