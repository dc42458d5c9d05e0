#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// NeuFlow-V2's local correlation from the features directly (as the CPU does): per pixel, dot
// products with the 10×10 integer neighbours of floor(p + flow) in frame 1, blended with the
// shared bilinear weights into the 9×9 window. Channel i*9 + j holds offset (dx = i - 4,
// dy = j - 4); positions outside frame 1 read as zero. Planar tensors throughout.
#include "common.glsl"
layout(std430, binding = 0) readonly buffer F0 { VALUE f0[]; };
layout(std430, binding = 1) readonly buffer F1 { VALUE f1[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
layout(std430, binding = 3) readonly buffer Flow { VALUE flow[]; };
#include "params/local_correlation_params.h"

const int R = 4, WIN = 9, N = 10;

void main() {
  const int plane = p.h * p.w;
  const float norm = inversesqrt(float(p.channels));
  // Zero as a run-time value, not a literal: VALUE(0.0) is a 16-bit constant in the fp16
  // variant, and glslang 11 (Ubuntu 22.04's glslangValidator) emits it without declaring the
  // Float16 capability, an invalid module the validation layer rejects.
  const float zero = 0.0 * norm;
  FOR_EACH(pix, plane) {
    const int y = pix / p.w, x = pix - y * p.w;
    const float px = float(x) + float(flow[p.flow_off + pix]);
    const float py = float(y) + float(flow[p.flow_off + plane + pix]);
    if (!(abs(px) < 1e6 && abs(py) < 1e6)) {  // far outside (or not a number): all zero
      for (int k = 0; k < WIN * WIN; ++k) dst[p.out_off + k * plane + pix] = VALUE(zero);
      continue;
    }
    const float fx0 = floor(px), fy0 = floor(py);
    const float ax = px - fx0, ay = py - fy0;
    const int bx = int(fx0) - R, by = int(fy0) - R;
    float d[N * N];  // d[i * N + j]: neighbour (bx + i, by + j)
    for (int k = 0; k < N * N; ++k) d[k] = 0.0;
    for (int c = 0; c < p.channels; ++c) {
      const float a = float(f0[p.f0_off + c * plane + pix]) * norm;
      for (int j = 0; j < N; ++j) {
        const int qy = by + j;
        if (qy < 0 || qy >= p.h) continue;
        const int row = p.f1_off + c * plane + qy * p.w;
        for (int i = 0; i < N; ++i) {
          const int qx = bx + i;
          if (qx >= 0 && qx < p.w) d[i * N + j] = fma(a, float(f1[row + qx]), d[i * N + j]);
        }
      }
    }
    const float w00 = (1.0 - ax) * (1.0 - ay), w10 = ax * (1.0 - ay), w01 = (1.0 - ax) * ay, w11 = ax * ay;
    for (int i = 0; i < WIN; ++i) {
      for (int j = 0; j < WIN; ++j) {
        dst[p.out_off + (i * WIN + j) * plane + pix] = VALUE(w00 * d[i * N + j] + w10 * d[(i + 1) * N + j] +
                                                             w01 * d[i * N + j + 1] + w11 * d[(i + 1) * N + j + 1]);
      }
    }
  }
}
