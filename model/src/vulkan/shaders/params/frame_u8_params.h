// frame_u8.comp: a frame's 8-bit pixels as the network's planar 0..1 input, edge-padded.
#ifndef NEUFLOW_SHADER_FRAME_U8_PARAMS_H
#define NEUFLOW_SHADER_FRAME_U8_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(FrameU8Params)
  int in_w, in_h, out_w, out_h, pad_left, pad_top;
  int swap;  // 1: the frame is BGR
NEUFLOW_PUSH_CONSTANTS_END

#endif
