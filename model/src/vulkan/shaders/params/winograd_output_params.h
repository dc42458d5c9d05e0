// winograd_output (winograd_output.comp): products[36][out_c][tiles] transformed back (Aᵀ m A
// of F(4×4, 3×3)) into the planar output, with bias, addend and activation.
#ifndef NEUFLOW_SHADER_WINOGRAD_OUTPUT_PARAMS_H
#define NEUFLOW_SHADER_WINOGRAD_OUTPUT_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(WinogradOutputParams)
  int c, h, w, out_off;  // planar output (binding 2), channel 0 at out_off
  int tiles_x, tiles;
  int bias_off;          // in binding 0; < 0: none
  int add_off;           // the addend (binding 3), shaped as the output; < 0: none
  int act;               // one of activation.h's codes
NEUFLOW_PUSH_CONSTANTS_END

#endif
