#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// A frame's 8-bit interleaved pixels (3 bytes a pixel, rows packed, read 4 bytes a word) as the
// network's planar [3][H][W] input in 0..1, as prepare_input() makes it on the CPU: centred in
// edge-replicated padding, with the first and third channels exchanged when `swap` is set.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer In { uint words[]; };
layout(std430, binding = 2) writeonly buffer Out { VALUE dst[]; };
#include "params/frame_u8_params.h"

uint byte_at(int i) { return (words[i >> 2] >> (8 * (i & 3))) & 0xffu; }

void main() {
  const int plane = p.out_w * p.out_h;
  FOR_EACH(i, plane) {
    const int y = i / p.out_w, x = i - y * p.out_w;
    const int sx = clamp(x - p.pad_left, 0, p.in_w - 1), sy = clamp(y - p.pad_top, 0, p.in_h - 1);
    const int pixel = 3 * (sy * p.in_w + sx);
    for (int c = 0; c < 3; ++c) {
      const int from = p.swap != 0 ? 2 - c : c;
      dst[c * plane + i] = VALUE(float(byte_at(pixel + from)) * (1.0 / 255.0));
    }
  }
}
