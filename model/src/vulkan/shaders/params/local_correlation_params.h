// local_correlation.comp: the 9×9 local correlation of f0 with f1 around each pixel's flow.
#ifndef NEUFLOW_SHADER_LOCAL_CORRELATION_PARAMS_H
#define NEUFLOW_SHADER_LOCAL_CORRELATION_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(LocalCorrelationParams)
  int h, w, channels, f0_off, f1_off, flow_off, out_off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
