#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// NeuFlow-V2's local correlation from the features directly (as the CPU does): per pixel, dot
// products with the 10×10 integer neighbours of floor(p + flow) in frame 1, blended with the
// shared bilinear weights into the 9×9 window. Channel i*9 + j holds offset (dx = i - 4,
// dy = j - 4); positions outside frame 1 read as zero. Planar tensors throughout.
// A workgroup takes 16 pixels, 10 invocations each: invocation row j sums the 10 dot products
// of neighbour row j (10 live accumulators, not 100), the rows meet in workgroup memory, and
// rows 0-8 then blend and write the window's row j for their pixel.
// With APPLY_UPDATE it is also the end of the refinement's previous step (refine_update.comp's
// arithmetic, in the same dispatch): the flow is the stored flow plus conv3's delta, written
// back (and into the step input's flow channels) once every invocation of the block has read
// it; the clamped hidden state goes into the step input's hidden channels. Without a previous
// step (update_off < 0, a scale's first correlation) it starts the step input instead: the flow
// as it is into its flow channels, zeros into its hidden ones.
layout(local_size_x = 16, local_size_y = 10) in;
layout(std430, binding = 0) readonly buffer F0 { VALUE f0[]; };
layout(std430, binding = 1) readonly buffer F1 { VALUE f1[]; };
layout(std430, binding = 2) buffer Out { VALUE dst[]; };
#ifdef APPLY_UPDATE
layout(std430, binding = 3) buffer Flow { VALUE flow[]; };
layout(std430, binding = 4) readonly buffer Update { VALUE update[]; };  // conv3's [delta 2, hidden 64]
#else
layout(std430, binding = 3) readonly buffer Flow { VALUE flow[]; };
#endif
#include "params/local_correlation_params.h"

const int R = 4, WIN = 9, N = 10, PIXELS = 16;
shared float sums[N][N][PIXELS];  // [row j][column i][pixel]: the dot product with (bx + i, by + j)

void main() {
  const int plane = p.h * p.w;
  const float norm = inversesqrt(float(p.channels));
  const int lx = int(gl_LocalInvocationID.x), j = int(gl_LocalInvocationID.y);
  // Whole blocks loop together, so every invocation reaches every barrier.
  for (int block = int(gl_WorkGroupID.x) * PIXELS; block < plane; block += int(gl_NumWorkGroups.x) * PIXELS) {
    const int pix = block + lx;
    float ax = 0.0, ay = 0.0;
    float d[N];
    for (int i = 0; i < N; ++i) d[i] = 0.0;
    VALUE fx = VALUE(0.0), fy = VALUE(0.0);
    if (pix < plane) {
      const int y = pix / p.w, x = pix - y * p.w;
      fx = flow[p.flow_off + pix];
      fy = flow[p.flow_off + plane + pix];
#ifdef APPLY_UPDATE
      if (p.update_off >= 0) {
        fx = VALUE(float(fx) + float(update[p.update_off + pix]));
        fy = VALUE(float(fy) + float(update[p.update_off + plane + pix]));
      }
      for (int c = j; c < 64; c += N) {
        dst[p.hidden_off + c * plane + pix] =
            p.update_off >= 0 ? VALUE(clamp(float(update[p.update_off + (2 + c) * plane + pix]), -4.0, 4.0)) : VALUE(0.0);
      }
#endif
      const float px = float(x) + float(fx);
      const float py = float(y) + float(fy);
      if (abs(px) < 1e6 && abs(py) < 1e6) {  // far outside (or not a number): all zero
        const float fx0 = floor(px), fy0 = floor(py);
        ax = px - fx0;
        ay = py - fy0;
        const int bx = int(fx0) - R, qy = int(fy0) - R + j;
        if (qy >= 0 && qy < p.h) {
          for (int c = 0; c < p.channels; ++c) {
            const float a = float(f0[p.f0_off + c * plane + pix]) * norm;
            const int row = p.f1_off + c * plane + qy * p.w;
            for (int i = 0; i < N; ++i) {
              const int qx = bx + i;
              if (qx >= 0 && qx < p.w) d[i] = fma(a, float(f1[row + qx]), d[i]);
            }
          }
        }
      }
    }
    for (int i = 0; i < N; ++i) sums[j][i][lx] = d[i];
    barrier();
#ifdef APPLY_UPDATE
    // Every invocation of this pixel has read its flow (before the barrier).
    if (pix < plane && j == 0) {
      if (p.update_off >= 0) {
        flow[p.flow_off + pix] = fx;
        flow[p.flow_off + plane + pix] = fy;
      }
      dst[p.flow_copy_off + pix] = fx;
      dst[p.flow_copy_off + plane + pix] = fy;
    }
#endif
    if (pix < plane && j < WIN) {
      const float w00 = (1.0 - ax) * (1.0 - ay), w10 = ax * (1.0 - ay), w01 = (1.0 - ax) * ay, w11 = ax * ay;
      for (int i = 0; i < WIN; ++i) {
        dst[p.out_off + (i * WIN + j) * plane + pix] =
            VALUE(w00 * sums[j][i][lx] + w10 * sums[j][i + 1][lx] + w01 * sums[j + 1][i][lx] + w11 * sums[j + 1][i + 1][lx]);
      }
    }
    barrier();  // the next block writes sums again
  }
}
