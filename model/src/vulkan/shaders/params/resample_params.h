// resample.comp: channels copied, nearest-neighbour upsampled by factor, optionally through ReLU, scaled.
#ifndef NEUFLOW_SHADER_RESAMPLE_PARAMS_H
#define NEUFLOW_SHADER_RESAMPLE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(ResampleParams)
  int channels, in_h, in_w, in_off, out_off, factor;
  int relu;  // 1: through ReLU
  float scale;
NEUFLOW_PUSH_CONSTANTS_END

#endif
