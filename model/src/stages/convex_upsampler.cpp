#include "stages/convex_upsampler.hpp"

#include <algorithm>
#include <cmath>

#include "dnnl/context.hpp"
#include "ops/feature_ops.hpp"

namespace neuflow::model {

namespace {
constexpr int kFactor = 8;
constexpr int kNeighbours = 9;
}  // namespace

ConvexUpsampler::ConvexUpsampler(const NetworkWeights& w, int h8, int w8, ScratchArena& arena)
    : input_(h8, w8, 130) {
  conv1_.emplace(w.upsample_conv1, ConvParams{1, 1, Activation::relu}, nhwc_desc(h8, w8, 130), arena);
  conv2_.emplace(w.upsample_conv2, ConvParams{1, 1, Activation::relu}, conv1_->output_desc(), arena);
  // The mask in 8-channel blocks: channel k*64 + a*8 + b is block k*8 + a, lane b, so the
  // combination below reads it in place without a conversion to NHWC.
  conv3_.emplace(w.upsample_conv3, ConvParams{1, 0, Activation::none}, conv2_->output_desc(), arena,
                 dnnl::memory::desc({1, 576, h8, w8}, dnnl::memory::data_type::f32,
                                    dnnl::memory::format_tag::nChw8c));
}

void ConvexUpsampler::run(dnnl::stream& stream, const Tensor& flow8, const Tensor& image_features, Tensor& flow) {
  copy_channels(all_channels(flow8), input_, 0);
  copy_channels(all_channels(image_features), input_, 2);
  const auto& mask_memory = conv3_->run(stream, conv2_->run(stream, conv1_->run(stream, wrap_nhwc(input_))));
  stream.wait();
  const auto* mask = static_cast<const float*>(mask_memory.get_data_handle());

  const int h8 = flow8.h, w8 = flow8.w;
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
      // mask value (k, a, b) at this pixel: block (k * 8 + a), lane b.
      const std::size_t pixel = static_cast<std::size_t>(y) * w8 + x;
      const std::size_t plane = static_cast<std::size_t>(h8) * w8 * kFactor;
      const auto m = [&](int k, int a, int b) { return mask[(k * kFactor + a) * plane + pixel * kFactor + b]; };
      for (int a = 0; a < kFactor; ++a) {
        for (int b = 0; b < kFactor; ++b) {
          float mx = m(0, a, b);
          for (int k = 1; k < kNeighbours; ++k) mx = std::max(mx, m(k, a, b));
          float sum = 0.f, u = 0.f, v = 0.f;
          for (int k = 0; k < kNeighbours; ++k) {
            const float e = std::exp(m(k, a, b) - mx);
            sum += e;
            u += e * nu[k];
            v += e * nv[k];
          }
          float* out = flow.pixel(y * kFactor + a, x * kFactor + b);
          out[0] = kFactor * u / sum;
          out[1] = kFactor * v / sum;
        }
      }
    }
  }
}

}  // namespace neuflow::model
