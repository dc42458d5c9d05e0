// conv2d (matmul.comp with IMPLICIT_CONV): out = act(alpha · W ⊛ in + bias (+ addend)).
// Offsets are in elements of their binding; a negative bias_off or add_off means none.
#ifndef NEUFLOW_SHADER_CONV2D_PARAMS_H
#define NEUFLOW_SHADER_CONV2D_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(Conv2dParams)
  int in_c, in_h, in_w, in_off;      // B: planar input, channel 0 at in_off (binding 1)
  int out_c, out_h, out_w, out_off;  // C: planar output, channel 0 at out_off (binding 2)
  int kernel, stride, pad, act;      // act: one of activation.h's codes
  int w_off;                         // A: OIHW weights at w_off in binding 0
  int bias_off;                      // in binding 0 (with the weights)
  int add_off;                       // the addend in binding 3, shaped as C
  float alpha;
NEUFLOW_PUSH_CONSTANTS_END

#endif
