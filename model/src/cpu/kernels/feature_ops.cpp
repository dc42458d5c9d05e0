#include "kernels/feature_ops.hpp"

#include <algorithm>
#include <stdexcept>

namespace neuflow::model {

void copy_channels(const ChannelSlice& src, Tensor& dst, int dst_offset, bool relu) {
  if (src.h() != dst.h || src.w() != dst.w || dst_offset + src.channels > dst.c) {
    throw std::logic_error("copy_channels: shapes do not fit");
  }
#pragma omp parallel for
  for (int y = 0; y < dst.h; ++y) {
    for (int x = 0; x < dst.w; ++x) {
      const float* s = src.pixel(y, x);
      float* d = dst.pixel(y, x) + dst_offset;
      if (relu) {
        for (int c = 0; c < src.channels; ++c) d[c] = std::max(s[c], 0.f);
      } else {
        std::copy(s, s + src.channels, d);
      }
    }
  }
}

void upsample_nearest_2x(const ChannelSlice& src, Tensor& dst, int dst_offset, float scale, bool relu) {
  if (2 * src.h() != dst.h || 2 * src.w() != dst.w || dst_offset + src.channels > dst.c) {
    throw std::logic_error("upsample_nearest_2x: shapes do not fit");
  }
#pragma omp parallel for
  for (int y = 0; y < dst.h; ++y) {
    for (int x = 0; x < dst.w; ++x) {
      const float* s = src.pixel(y / 2, x / 2);
      float* d = dst.pixel(y, x) + dst_offset;
      for (int c = 0; c < src.channels; ++c) {
        const float v = relu ? std::max(s[c], 0.f) : s[c];
        d[c] = v * scale;
      }
    }
  }
}

Tensor extract_channels(const ChannelSlice& src) {
  Tensor out(src.h(), src.w(), src.channels);
  copy_channels(src, out, 0);
  return out;
}

}  // namespace neuflow::model
