#pragma once
// The activations a convolution or a linear layer applies to its output, fused where the
// backend can (oneDNN post-ops, the product shaders' activation codes).

namespace neuflow::model {

enum class Activation { none, leaky_relu, relu, gelu };

}  // namespace neuflow::model
