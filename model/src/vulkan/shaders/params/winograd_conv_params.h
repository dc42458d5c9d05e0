// winograd_conv (winograd_conv.comp): a stride-1 3×3 convolution with padding 1 by F(4×4, 3×3)
// in one dispatch, with bias, addend and activation. Its OIHW filters and bias are in binding 0
// (the weights), transformed as they are loaded.
#ifndef NEUFLOW_SHADER_WINOGRAD_CONV_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_CONV_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(WinogradConvParams)
  int in_c, h, w, in_off;  // planar input (binding 1), channel 0 at in_off; the output is as large
  int out_c, out_off;      // planar output (binding 2), channel 0 at out_off
  int tiles_x, tiles;      // 4×4 output tiles per row, in all
  int w_off;               // in binding 0
  int bias_off;            // in binding 0; < 0: none
  int add_off;             // the addend (binding 3), shaped as the output; < 0: none
  int act;                 // one of activation.h's codes
NEUFLOW_PUSH_CONSTANTS_END

#endif
