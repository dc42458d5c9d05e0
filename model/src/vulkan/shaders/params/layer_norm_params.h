// layer_norm.comp: LayerNorm over each token of a [dim][tokens] list, plus an optional residual, then an optional folded BatchNorm.
#ifndef NEUFLOW_SHADER_LAYER_NORM_PARAMS_H
#define NEUFLOW_SHADER_LAYER_NORM_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(LayerNormParams)
  int dim, tokens, x_off, out_off;
  int res_off;  // < 0: no residual
  int gamma_off, beta_off;
  int scale_off, shift_off;  // < 0: no folded BatchNorm after it (out = out · scale + shift)
  // layer_norm_unstacked: the tokens are both frames' (frame 0's first), `split` each; frame 1's
  // go to binding 4 from out2_off, and each frame's output planes are `split` tokens apart.
  int split, out2_off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
