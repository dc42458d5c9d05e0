// convex_upsample.comp: the 1/8 flow convex-upsampled by its 9-neighbour masks to full size.
#ifndef NEUFLOW_SHADER_CONVEX_UPSAMPLE_PARAMS_H
#define NEUFLOW_SHADER_CONVEX_UPSAMPLE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(ConvexUpsampleParams)
  int h8, w8;
  int planar;  // != 0: the flow also into the planar tensor (binding 3), for a stage observer
NEUFLOW_PUSH_CONSTANTS_END

#endif
