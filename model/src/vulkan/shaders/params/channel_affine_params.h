// channel_affine.comp: x = x · scale[c] + shift[c] in place, per channel of a planar tensor.
#ifndef NEUFLOW_SHADER_CHANNEL_AFFINE_PARAMS_H
#define NEUFLOW_SHADER_CHANNEL_AFFINE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(ChannelAffineParams)
  int channels, plane, x_off, scale_off, shift_off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
