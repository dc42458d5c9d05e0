// winograd_conv_step (winograd_conv.comp with STEP_CORRELATION) and its fragment forms: the
// refinement step's conv3 for its hidden state only, clamped into the next step input, beside
// conv3's delta, the new flow and the next step's local correlation in the same dispatch. The
// convolution's fields are winograd_conv_params.h's (no input in parts); then the grid's split
// and the correlation's fields (local_correlation_params.h's, the correlation's output at
// corr_off), with where conv3's first two filters and biases are in binding 0.
// winograd_conv_step_end (STEP_UPDATE_ONLY): a scale's last step, the same without the
// correlation (its fields ignored), the new flow also upsampled by `factor` (nearest) and scaled
// into binding 5 at resampled_off (< 0: not).
#ifndef NEUFLOW_SHADER_WINOGRAD_CONV_STEP_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_CONV_STEP_PARAMS_H
#include "activation.h"

// The correlation's workgroups take blocks of this many pixels (their 192 invocations: 10 rows
// of 19 pixels, 2 idle).
NEUFLOW_SHADER_CONST(kStepCorrelationPixels, 19)

NEUFLOW_PUSH_CONSTANTS(WinogradConvStepParams)
  int in_c, h, w, in_off;
  int out_c, out_off;
  int tiles_x, tiles;
  int w_off;
  int filters_off;
  int filters_in, filters_out;
  int bias_off;
  int add_off;
  int act;
  int conv_groups, tile_groups;  // the convolution's workgroups (first), and its tile groups per channel group
  int channels, f0_off, f1_off, flow_off, corr_off, flow_copy_off;
  int delta_w_off, delta_bias_off;
  int resampled_off, factor;
  float scale;
NEUFLOW_PUSH_CONSTANTS_END

#endif
