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
    : input_(h8, w8, 130) {
  conv1_.emplace(w.upsample_conv1, ConvParams{1, 1, Activation::relu}, nhwc_desc(h8, w8, 130), context);
  conv2_.emplace(w.upsample_conv2, ConvParams{1, 1, Activation::relu}, conv1_->output_desc(), context);
  // The mask in 8-channel blocks: channel k*64 + a*8 + b is block k*8 + a, lane b, so the
  // combination below reads it in place without a conversion to NHWC.
  conv3_.emplace(w.upsample_conv3, ConvParams{1, 0, Activation::none}, conv2_->output_desc(), context,
                 dnnl::memory::desc({1, 576, h8, w8}, dnnl::memory::data_type::f32,
                                    dnnl::memory::format_tag::nChw8c));
}

void ConvexUpsampler::run(dnnl::stream& stream, const Tensor& flow8, const Tensor& image_features, Tensor& flow) {
  copy_channels(all_channels(flow8), input_, 0);
  copy_channels(all_channels(image_features), input_, 2);
  const auto& mask_memory = conv3_->run(stream, conv2_->run(stream, conv1_->run(stream, wrap_nhwc(input_))));
  stream.wait();
  // In 8-channel blocks the mask is a row-major [9, 64 · h8 · w8] matrix: row k holds the
  // weight logits of neighbour k for every output pixel, contiguous in the output's x within
  // a coarse pixel. The softmax over the 9 neighbours runs in three vectorizable passes:
  // subtract each column's max, exp (oneDNN's jitted eltwise), then normalized weighted sums.
  const int h8 = flow8.h, w8 = flow8.w;
  const std::size_t plane = static_cast<std::size_t>(h8) * w8 * kFactor * kFactor;
  auto* mask = static_cast<float*>(mask_memory.get_data_handle());
  const long columns = static_cast<long>(plane);
#pragma omp parallel for
  for (long block = 0; block < columns; block += kFactor) {
    float mx[kFactor];
    for (int b = 0; b < kFactor; ++b) mx[b] = mask[block + b];
    for (int k = 1; k < kNeighbours; ++k) {
      for (int b = 0; b < kFactor; ++b) mx[b] = std::max(mx[b], mask[k * plane + block + b]);
    }
    for (int k = 0; k < kNeighbours; ++k) {
      for (int b = 0; b < kFactor; ++b) mask[k * plane + block + b] -= mx[b];
    }
  }
  exp_in_place(stream, mask, kNeighbours * plane);
  stream.wait();

  flow.resize(h8 * kFactor, w8 * kFactor, 2);
#pragma omp parallel for
  for (int y = 0; y < h8; ++y) {
    for (int x = 0; x < w8; ++x) {
      // The 3×3 neighbourhood of the coarse flow, zero outside; k = 3 * ky + kx.
      float nu[kNeighbours], nv[kNeighbours];
      for (int k = 0; k < kNeighbours; ++k) {
        const int yy = y + k / 3 - 1, xx = x + k % 3 - 1;
        const bool inside = yy >= 0 && yy < h8 && xx >= 0 && xx < w8;
        nu[k] = inside ? flow8.pixel(yy, xx)[0] : 0.f;
        nv[k] = inside ? flow8.pixel(yy, xx)[1] : 0.f;
      }
      // Weight of neighbour k for output (8y + a, 8x + b): block (k * 8 + a), lane b.
      const std::size_t pixel = (static_cast<std::size_t>(y) * w8 + x) * kFactor;
      for (int a = 0; a < kFactor; ++a) {
        float sum[kFactor] = {}, u[kFactor] = {}, v[kFactor] = {};
        for (int k = 0; k < kNeighbours; ++k) {
          const float* e = mask + static_cast<std::size_t>(k) * plane + a * (plane / kFactor) + pixel;
          for (int b = 0; b < kFactor; ++b) {
            sum[b] += e[b];
            u[b] += e[b] * nu[k];
            v[b] += e[b] * nv[k];
          }
        }
        float* out = flow.pixel(y * kFactor + a, x * kFactor);
        for (int b = 0; b < kFactor; ++b) {
          out[2 * b] = kFactor * u[b] / sum[b];
          out[2 * b + 1] = kFactor * v[b] / sum[b];
        }
      }
    }
  }
}

}  // namespace neuflow::model
