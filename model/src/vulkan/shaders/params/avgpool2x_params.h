// avgpool2x.comp: each channel of a planar tensor 2×2-average-pooled.
#ifndef NEUFLOW_SHADER_AVGPOOL2X_PARAMS_H
#define NEUFLOW_SHADER_AVGPOOL2X_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(Avgpool2xParams)
  int channels, in_h, in_w;
NEUFLOW_PUSH_CONSTANTS_END

#endif
