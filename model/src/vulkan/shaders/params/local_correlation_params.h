// local_correlation.comp: the 9×9 local correlation of f0 with f1 around each pixel's flow
// (local_correlation_update: after the previous refinement step's update).
#ifndef NEUFLOW_SHADER_LOCAL_CORRELATION_PARAMS_H
#define NEUFLOW_SHADER_LOCAL_CORRELATION_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(LocalCorrelationParams)
  int h, w, channels, f0_off, f1_off, flow_off, out_off;
  // local_correlation_update only: where conv3's output is (< 0: no previous step, the step
  // input's first values), and where the step input's hidden state and flow channels are (in
  // the output's buffer).
  int update_off, hidden_off, flow_copy_off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
