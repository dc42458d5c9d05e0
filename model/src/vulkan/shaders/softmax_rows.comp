#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// In place: each row of a [rows][cols] matrix becomes its softmax. One workgroup per row.
layout(local_size_x = 256) in;
layout(std430, binding = 2) buffer Data { VALUE data[]; };
#include "params/softmax_rows_params.h"
shared float partial[256];

void main() {
  const int row = int(gl_WorkGroupID.x), t = int(gl_LocalInvocationID.x);
  if (row >= p.rows) return;  // uniform per workgroup
  const int base = p.off + row * p.cols;
  float m = -3.402823e38;
  for (int i = t; i < p.cols; i += 256) m = max(m, float(data[base + i]));
  partial[t] = m;
  barrier();
  for (int s = 128; s > 0; s >>= 1) {
    if (t < s) partial[t] = max(partial[t], partial[t + s]);
    barrier();
  }
  m = partial[0];
  barrier();
  float sum = 0.0;
  for (int i = t; i < p.cols; i += 256) {
    const float e = exp(float(data[base + i]) - m);
    data[base + i] = VALUE(e);
    sum += e;
  }
  partial[t] = sum;
  barrier();
  for (int s = 128; s > 0; s >>= 1) {
    if (t < s) partial[t] += partial[t + s];
    barrier();
  }
  const float inv = 1.0 / partial[0];
  for (int i = t; i < p.cols; i += 256) data[base + i] = VALUE(float(data[base + i]) * inv);
}
