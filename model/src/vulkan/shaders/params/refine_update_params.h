// refine_update.comp: the refinement's hidden state and flow updated from conv3's output.
#ifndef NEUFLOW_SHADER_REFINE_UPDATE_PARAMS_H
#define NEUFLOW_SHADER_REFINE_UPDATE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(RefineUpdateParams)
  int plane, hidden_off, flow_in_off, flow_off;
NEUFLOW_PUSH_CONSTANTS_END

#endif
