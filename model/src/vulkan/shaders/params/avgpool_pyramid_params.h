// avgpool_pyramid.comp: a planar tensor 2×2-average-pooled three times in one pass
// (frame_pyramid: from a frame's 8-bit pixels, which it also writes as the network's input).
#ifndef NEUFLOW_SHADER_AVGPOOL_PYRAMID_PARAMS_H
#define NEUFLOW_SHADER_AVGPOOL_PYRAMID_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(AvgpoolPyramidParams)
  int channels, in_h, in_w;
  // frame_pyramid only: the 8-bit frame's size, where it sits in the input, 1 for BGR.
  int frame_w, frame_h, pad_left, pad_top, swap;
NEUFLOW_PUSH_CONSTANTS_END

#endif
