// softmax_rows.comp: a softmax over each row of a row-major block, in place.
#ifndef NEUFLOW_SHADER_SOFTMAX_ROWS_PARAMS_H
#define NEUFLOW_SHADER_SOFTMAX_ROWS_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(SoftmaxRowsParams)
  int rows, cols, off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
