// The activations the product shaders fuse (matmul.comp's activate()), as the `act` member of
// Conv2dParams and MatmulParams.
#ifndef NEUFLOW_SHADER_ACTIVATION_H
#define NEUFLOW_SHADER_ACTIVATION_H
#include "interface.h"

NEUFLOW_SHADER_CONST(kActNone, 0)
NEUFLOW_SHADER_CONST(kActLeakyRelu, 1)  // LeakyReLU(0.1)
NEUFLOW_SHADER_CONST(kActRelu, 2)
NEUFLOW_SHADER_CONST(kActGelu, 3)        // exact (erf) GELU
NEUFLOW_SHADER_CONST(kActClamp4, 4)      // Hardtanh(-4, 4): the refinement's hidden state

#endif
