// axpby.comp: out = a · x + b · y over count elements.
#ifndef NEUFLOW_SHADER_AXPBY_PARAMS_H
#define NEUFLOW_SHADER_AXPBY_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(AxpbyParams)
  int count, x_off, y_off, out_off;
  float a, b;
NEUFLOW_PUSH_CONSTANTS_END

#endif
