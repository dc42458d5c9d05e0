// winograd_input (winograd_input.comp): the 6×6 input tiles of a stride-1 3×3 convolution with
// padding 1, transformed (Bᵀ d B of F(4×4, 3×3)) into points[36][c][tiles] (fp32).
#ifndef NEUFLOW_SHADER_WINOGRAD_INPUT_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_INPUT_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(WinogradInputParams)
  int c, h, w, in_off;  // planar input (binding 0), channel 0 at in_off
  int tiles_x, tiles;   // 4×4 output tiles per row, in all
NEUFLOW_PUSH_CONSTANTS_END

#endif
