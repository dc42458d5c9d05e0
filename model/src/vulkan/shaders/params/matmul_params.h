// matmul (matmul.comp): C = act(alpha · A · B + bias), every operand with a row and a column
// stride (so transposes are free). A's bias is per row of C, in A's binding; < 0: none.
#ifndef NEUFLOW_SHADER_MATMUL_PARAMS_H
#define NEUFLOW_SHADER_MATMUL_PARAMS_H
#include "activation.h"

NEUFLOW_PUSH_CONSTANTS(MatmulParams)
  int m, n, k;
  int a_off, a_rs, a_cs;
  int b_off, b_rs, b_cs;
  int c_off, c_rs, c_cs;
  int bias_off;
  int act;  // one of activation.h's codes
  float alpha;
NEUFLOW_PUSH_CONSTANTS_END

#endif
