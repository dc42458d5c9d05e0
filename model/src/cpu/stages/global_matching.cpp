#include "stages/global_matching.hpp"

#include <algorithm>
#include <cmath>

#include "dnnl/matrix_ops.hpp"

namespace neuflow::model {

namespace {
constexpr int kScoreBlockFloats = 1 << 20;

void gather(const ChannelSlice& f, Tensor& out) {
  const int c = f.channels;
  for (int y = 0; y < f.h(); ++y) {
    for (int x = 0; x < f.w(); ++x) {
      std::copy_n(f.pixel(y, x), c, out.data.data() + (static_cast<std::size_t>(y) * f.w() + x) * c);
    }
  }
}
}  // namespace

GlobalMatching::GlobalMatching(int h16, int w16, int channels, PlanContext& context)
    : h_(h16), w_(w16), channels_(channels) {
  const int l = h16 * w16;
  block_rows_ = std::clamp(kScoreBlockFloats / std::max(l, 1), 1, l);
  context.arena.make_tensor(a_, 1, l, channels);
  context.arena.make_tensor(b_, 1, l, channels);
  context.arena.make_tensor(scores_, 1, block_rows_, l);
  correspondence_.resize(static_cast<std::size_t>(l) * 2);
  grid_.resize(static_cast<std::size_t>(l) * 2);
  for (int y = 0; y < h16; ++y) {
    for (int x = 0; x < w16; ++x) {
      grid_[2 * (y * w16 + x)] = static_cast<float>(x);
      grid_[2 * (y * w16 + x) + 1] = static_cast<float>(y);
    }
  }
}

void GlobalMatching::run(dnnl::stream& stream, const ChannelSlice& f0, const ChannelSlice& f1, Tensor& flow) {
  const int l = h_ * w_;
  gather(f0, a_);
  gather(f1, b_);
  const float alpha = 1.f / std::sqrt(static_cast<float>(channels_));
  for (int r0 = 0; r0 < l; r0 += block_rows_) {
    const int n = std::min(block_rows_, l - r0);
    matmul(stream, {a_.data.data() + static_cast<std::size_t>(r0) * channels_, n, channels_, channels_},
           {b_.data.data(), l, channels_, channels_}, scores_.data.data(), l, {.transpose_b = true, .alpha = alpha});
    softmax_rows(stream, scores_.data.data(), n, l);
    matmul(stream, {scores_.data.data(), n, l, l}, {grid_.data(), l, 2, 2}, correspondence_.data() + 2 * r0, 2);
  }
  stream.wait();
  flow.resize(h_, w_, 2);
  for (std::size_t i = 0; i < correspondence_.size(); ++i) flow.data[i] = correspondence_[i] - grid_[i];
}

}  // namespace neuflow::model
