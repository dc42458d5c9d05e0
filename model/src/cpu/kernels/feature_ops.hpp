#pragma once
// Small per-pixel operations on NHWC tensors between the convolution chains.
#include <dnnl.hpp>

#include "tensor.hpp"

namespace neuflow::model {

// A channel range [offset, offset + channels) of an NHWC tensor, read in place.
struct ChannelSlice {
  const Tensor* tensor;
  int offset;
  int channels;

  const float* pixel(int y, int x) const { return tensor->pixel(y, x) + offset; }
  int h() const { return tensor->h; }
  int w() const { return tensor->w; }
  int stride() const { return tensor->c; }
};

inline ChannelSlice all_channels(const Tensor& t) { return {&t, 0, t.c}; }

// Copies `src` into channels [dst_offset, dst_offset + src.channels) of `dst` (same size).
// With relu, negative values become 0.
void copy_channels(const ChannelSlice& src, Tensor& dst, int dst_offset, bool relu = false);

// Nearest-neighbour 2× upsampling of `src` into channels starting at dst_offset of `dst`
// (dst is 2h × 2w), each value multiplied by `scale`; relu first if asked.
void upsample_nearest_2x(const ChannelSlice& src, Tensor& dst, int dst_offset, float scale = 1.f, bool relu = false);

// A fresh tensor holding a copy of a channel range (for observers and tests).
Tensor extract_channels(const ChannelSlice& src);

}  // namespace neuflow::model
