#include "stages/convex_upsampler.hpp"

#include <algorithm>
#include <cmath>

#include "dnnl/context.hpp"
#include "dnnl/matrix_ops.hpp"
#include "ops/feature_ops.hpp"

namespace neuflow::model {

namespace {
constexpr int kFactor = 8;
constexpr int kNeighbours = 9;
}  // namespace

ConvexUpsampler::ConvexUpsampler(const NetworkWeights& w, int h8, int w8, PlanContext& context)
    : mask_head_(&w.upsample_conv3) {
  context.arena.make_tensor(input_, h8, w8, 130);  // [flow 2, image features 128], written whole by run()
  conv1_.emplace(w.upsample_conv1, ConvParams{1, 1, Activation::relu}, nhwc_desc(h8, w8, 130), context);
  conv1_->release_scratch(context.arena);
  context.arena.release(input_);  // read by conv1 only
  conv2_.emplace(w.upsample_conv2, ConvParams{1, 1, Activation::relu}, conv1_->output_desc(), context,
                 nhwc_desc(h8, w8, w.upsample_conv2.out_channels));
  conv2_->release_scratch(context.arena);
  context.arena.release(conv1_->output());  // read by conv2 only
  // Written, band by band, while conv2's output is read: made after it, so never on it.
  context.arena.make_tensor(flow_, h8 * kFactor, w8 * kFactor, 2);
  // Bands of about 1 MiB of logits: a few coarse rows, always whole rows.
  constexpr std::size_t kBandBytes = 1 << 20;
  const std::size_t row_bytes = static_cast<std::size_t>(w8) * kNeighbours * kFactor * kFactor * sizeof(float);
  band_rows_ = std::clamp(static_cast<int>(kBandBytes / row_bytes), 1, h8);
  band_.resize(static_cast<std::size_t>(band_rows_) * w8 * kNeighbours * kFactor * kFactor);
}

const Tensor& ConvexUpsampler::run(dnnl::stream& stream, const Tensor& flow8, const Tensor& image_features) {
  Tensor& flow = flow_;
  copy_channels(all_channels(flow8), input_, 0);
  copy_channels(all_channels(image_features), input_, 2);
  const auto& features_memory = conv2_->run(stream, conv1_->run(stream, wrap_nhwc(input_)));
  stream.wait();
  const auto* features = static_cast<const float*>(features_memory.get_data_handle());
  const int h8 = flow8.h, w8 = flow8.w;
  const int depth = mask_head_->in_channels;
  constexpr int kWeights = kFactor * kFactor;      // output pixels per coarse pixel
  constexpr int kLogits = kNeighbours * kWeights;  // channel k · 64 + a · 8 + b
  for (int y0 = 0; y0 < h8; y0 += band_rows_) {
    const int rows = std::min(band_rows_, h8 - y0);
    const int pixels = rows * w8;
    float* logits = band_.data();
    matmul(stream, {features + static_cast<std::size_t>(y0) * w8 * depth, pixels, depth, depth},
           {mask_head_->weight.data(), kLogits, depth, depth}, logits, kLogits,
           {.transpose_b = true, .bias = mask_head_->bias.data()});
    stream.wait();
    // Softmax over the 9 neighbours of each output pixel: subtract the max (64 output pixels
    // side by side, so the loops vectorize), exp by oneDNN, then normalized weighted sums.
#pragma omp parallel for
    for (int p = 0; p < pixels; ++p) {
      float* l = logits + static_cast<std::size_t>(p) * kLogits;
      float mx[kWeights];
      std::copy_n(l, kWeights, mx);
      for (int k = 1; k < kNeighbours; ++k) {
        for (int i = 0; i < kWeights; ++i) mx[i] = std::max(mx[i], l[k * kWeights + i]);
      }
      for (int k = 0; k < kNeighbours; ++k) {
        for (int i = 0; i < kWeights; ++i) l[k * kWeights + i] -= mx[i];
      }
    }
    exp_in_place(stream, logits, static_cast<std::size_t>(pixels) * kLogits);
    stream.wait();
#pragma omp parallel for
    for (int p = 0; p < pixels; ++p) {
      const int y = y0 + p / w8, x = p % w8;
      // The 3×3 neighbourhood of the coarse flow, zero outside; k = 3 * ky + kx.
      float nu[kNeighbours], nv[kNeighbours];
      for (int k = 0; k < kNeighbours; ++k) {
        const int yy = y + k / 3 - 1, xx = x + k % 3 - 1;
        const bool inside = yy >= 0 && yy < h8 && xx >= 0 && xx < w8;
        nu[k] = inside ? flow8.pixel(yy, xx)[0] : 0.f;
        nv[k] = inside ? flow8.pixel(yy, xx)[1] : 0.f;
      }
      const float* e = logits + static_cast<std::size_t>(p) * kLogits;
      float sum[kWeights] = {}, u[kWeights] = {}, v[kWeights] = {};
      for (int k = 0; k < kNeighbours; ++k) {
        for (int i = 0; i < kWeights; ++i) {
          sum[i] += e[k * kWeights + i];
          u[i] += e[k * kWeights + i] * nu[k];
          v[i] += e[k * kWeights + i] * nv[k];
        }
      }
      // Weight i = 8a + b is output pixel (8y + a, 8x + b).
      for (int a = 0; a < kFactor; ++a) {
        float* out = flow.pixel(y * kFactor + a, x * kFactor);
        for (int b = 0; b < kFactor; ++b) {
          out[2 * b] = kFactor * u[a * kFactor + b] / sum[a * kFactor + b];
          out[2 * b + 1] = kFactor * v[a * kFactor + b] / sum[a * kFactor + b];
        }
      }
    }
  }
  return flow_;
}

}  // namespace neuflow::model
