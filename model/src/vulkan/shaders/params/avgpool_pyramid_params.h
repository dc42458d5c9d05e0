// avgpool_pyramid.comp: a planar tensor 2×2-average-pooled three times in one pass.
#ifndef NEUFLOW_SHADER_AVGPOOL_PYRAMID_PARAMS_H
#define NEUFLOW_SHADER_AVGPOOL_PYRAMID_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(AvgpoolPyramidParams)
  int channels, in_h, in_w;
NEUFLOW_PUSH_CONSTANTS_END

#endif
