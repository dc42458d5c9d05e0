// convex_upsample.comp: the 1/8 flow convex-upsampled by its 9-neighbour masks to full size.
#ifndef NEUFLOW_SHADER_CONVEX_UPSAMPLE_PARAMS_H
#define NEUFLOW_SHADER_CONVEX_UPSAMPLE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(ConvexUpsampleParams)
  int h8, w8;
NEUFLOW_PUSH_CONSTANTS_END

#endif
