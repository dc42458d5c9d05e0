#version 450
#extension GL_GOOGLE_include_directive : require
#include "precision.glsl"
// NeuFlow-V2's local correlation from the features directly (as the CPU does), 16 pixels a
// block (local_correlation_block.glsl). With APPLY_UPDATE it is also the end of the refinement's
// previous step (refine_update.comp's arithmetic, in the same dispatch), or without a previous
// step (update_off < 0, a scale's first correlation) the start of the step input: the flow as it
// is into its flow channels, zeros into its hidden ones.
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

shared float scratch[120 * 16];
#define CORRELATION_SCRATCH(i) scratch[i]
#define CORRELATION_PIXELS 16
#include "local_correlation_block.glsl"

void main() {
  const Correlation q = Correlation(p.h, p.w, p.channels, p.f0_off, p.f1_off, p.flow_off, p.out_off, p.update_off,
                                    p.hidden_off, p.flow_copy_off, 0, 0, 0, 0, -1, 1, 1.0);
  const int plane = p.h * p.w;
  // Whole blocks loop together, so every invocation reaches every barrier.
  for (int block = int(gl_WorkGroupID.x) * CORR_PIXELS; block < plane; block += int(gl_NumWorkGroups.x) * CORR_PIXELS) {
    correlate_block(q, block, int(gl_LocalInvocationID.x), int(gl_LocalInvocationID.y));
  }
}
