// resample.comp: channels copied, nearest-neighbour upsampled by factor, optionally through ReLU,
// scaled; from one source, or from two into consecutive channel ranges of the output.
#ifndef NEUFLOW_SHADER_RESAMPLE_PARAMS_H
#define NEUFLOW_SHADER_RESAMPLE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(ResampleParams)
  int channels, in_h, in_w, in_off, out_off, factor;  // the first source (binding 0)
  int relu;                                           // 1: through ReLU
  float scale;
  // The second source (binding 1), into the channels after the first's, upsampled to the same
  // plane; 0 channels: none.
  int channels2, in2_h, in2_w, in2_off, factor2;
  int relu2;
  float scale2;
NEUFLOW_PUSH_CONSTANTS_END

#endif
