#pragma once
// What a convolution computes besides its weights: stride, padding, the fused activation.

namespace neuflow::model {

enum class Activation { none, leaky_relu, relu, gelu };

struct ConvParams {
  int stride = 1;
  int pad = 0;
  Activation activation = Activation::none;
  // Adds a tensor given at run time to the convolution's result before the activation.
  // Used to add the per-pair constant part of the refinement's first convolution.
  bool accumulate = false;
};

}  // namespace neuflow::model
