#pragma once
// What a convolution computes besides its weights: stride, padding, the fused activation.

#include "graph/activation.hpp"

namespace neuflow::model {

struct ConvParams {
  int stride = 1;
  int pad = 0;
  Activation activation = Activation::none;
  // Adds a tensor given at run time to the convolution's result before the activation.
  // Used to add the per-pair constant part of the refinement's first convolution.
  bool accumulate = false;
  // Runs several times a pair (the 1/8 refinement's iterations): where F(6×6, 3×3) computes
  // fewer products, the time it saves there is worth its filters' extra memory (64 points a
  // channel pair against F(4×4)'s 36; on every layer, 95 MB more at 1920×1088). Layers that
  // run once a pair keep F(4×4) under the automatic choice.
  bool repeated = false;
};

}  // namespace neuflow::model
