// matmul_norm (matmul.comp, matmul_fragments.comp with LAYER_NORM): a matrix product whose
// every column (a token's channels) a workgroup computes whole, then LayerNorm over each column
// in the same dispatch (layer_norm_tile.glsl), with LayerNorm's residual, folded BatchNorm and
// unstacked output as layer_norm_params.h has them. The product's output is never written.
// matmul_mlp_norm (with MLP as well): two products, the first's output held in workgroup memory.
#ifndef NEUFLOW_SHADER_MATMUL_NORM_PARAMS_H
#define NEUFLOW_SHADER_MATMUL_NORM_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(MatmulNormParams)
  int m, n, k;  // m: the channels LayerNorm normalizes, at most kMatmulNormChannels
  int a_off, a_rs, a_cs;
  int b_off, b_rs, b_cs;
  int c_off, c_rs, c_cs;  // the LayerNorm's output (frame 0's, where split > 0)
  int bias_off;
  int act;  // one of activation.h's codes, before the LayerNorm
  float alpha;
  int res_off;  // < 0: no residual (binding 3, [m][n] planes)
  int gamma_off, beta_off;
  int scale_off, shift_off;  // < 0: no folded BatchNorm after it
  // > 0: the columns are both frames' tokens (frame 0's first), `split` each; frame 1's go to
  // binding 4 from out2_off, each frame's output planes `split` tokens apart.
  int split, out2_off;
  // matmul_mlp_norm (MLP): the product above (a_off, bias_off, act) is the MLP's first layer,
  // into `hidden` channels held in workgroup memory; the second, W2 · hidden with W2 at w2_off
  // (row-major, `hidden` columns), bias2_off and act2, is the one the LayerNorm takes.
  int hidden, w2_off, bias2_off, act2;
NEUFLOW_PUSH_CONSTANTS_END

// The rows one workgroup's tile holds: the cross-attention's channels; its MLP's hidden layer.
NEUFLOW_SHADER_CONST(kMatmulNormChannels, 192)
NEUFLOW_SHADER_CONST(kMlpHiddenChannels, 384)

#endif
