#pragma once
// NeuFlow-V2's local correlation, computed from the features directly instead of sampling an
// all-pairs volume: per pixel, dot products with the 10×10 integer neighbours of
// floor(p + flow), blended with the shared bilinear weights into the 9×9 window.
#include "kernels/feature_ops.hpp"
#include "network_dims.hpp"
#include "tensor.hpp"

namespace neuflow::model {

// Writes 81 channels per pixel into `out` starting at channel out_offset; channel i*9 + j
// holds the correlation at offset (dx = i - 4, dy = j - 4), scaled by 1/sqrt(channels).
// Positions outside frame 1 read as zero. f0, f1 and flow share the same h × w.
void local_correlation(const ChannelSlice& f0, const ChannelSlice& f1, const Tensor& flow, Tensor& out, int out_offset);

}  // namespace neuflow::model
