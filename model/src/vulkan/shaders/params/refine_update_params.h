// refine_update.comp: the refinement's hidden state and flow updated from conv3's output.
#ifndef NEUFLOW_SHADER_REFINE_UPDATE_PARAMS_H
#define NEUFLOW_SHADER_REFINE_UPDATE_PARAMS_H
#include "interface.h"

NEUFLOW_PUSH_CONSTANTS(RefineUpdateParams)
  int plane, w, hidden_off, flow_in_off, flow_off;
  int resampled_off;  // the new flow also into binding 1 from here; < 0: not
  int factor;         // ... upsampled by this (nearest)
  float scale;        // ... and scaled
NEUFLOW_PUSH_CONSTANTS_END

#endif
