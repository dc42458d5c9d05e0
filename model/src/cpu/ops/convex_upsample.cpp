#include <algorithm>
#include <stdexcept>

#include "dnnl/context.hpp"
#include "dnnl/matrix_ops.hpp"
#include "network_dims.hpp"
#include "ops/cpu_op.hpp"

namespace neuflow::model {

namespace {

constexpr int kFactor = kUpsampleFactor;
constexpr int kNeighbours = 9;
constexpr int kWeights = kFactor * kFactor;      // output pixels per coarse pixel
constexpr int kLogits = kNeighbours * kWeights;  // channel k · 64 + a · 8 + b

// The mask's 1×1 convolution is computed here, a band of coarse rows at a time, so its 576
// channels never exist for the whole image (75 MB at 1920×1088): the fused attribute the CPU
// plan gives this op.
class ConvexUpsampleOp final : public CpuOp {
 public:
  ConvexUpsampleOp(const graph::ConvexUpsample& op, OpBuild& b) : op_(op), head_(*b.fused_mask) {
    if (head_.weights->kernel_h != 1 || head_.stride != 1 || head_.pad != 0 || head_.act != Activation::none) {
      throw std::logic_error("the CPU's convex upsampling computes its mask from a plain 1×1 convolution");
    }
    const graph::TensorDesc& flow = b.tensors.desc(op.flow.tensor);
    // Bands of about 1 MiB of logits: a few coarse rows, always whole rows.
    constexpr std::size_t kBandBytes = 1 << 20;
    const std::size_t row_bytes = static_cast<std::size_t>(flow.w) * kLogits * sizeof(float);
    band_rows_ = std::clamp(static_cast<int>(kBandBytes / row_bytes), 1, flow.h);
    band_ = b.scratch.arena.make(dnnl::memory::desc({static_cast<long>(band_rows_) * flow.w * kLogits},
                                                    dnnl::memory::data_type::f32, dnnl::memory::format_tag::x));
    b.scratch.arena.release(band_);
  }

  void run(OpRun& pass) override {
    TensorStore& t = pass.tensors;
    const Tensor& features = t.nhwc(head_.in.tensor);
    const Tensor& flow8 = t.nhwc(op_.flow.tensor);
    Tensor& flow = t.nhwc(op_.out.tensor);
    const ConvWeights& w = *head_.weights;
    const int h8 = flow8.h, w8 = flow8.w, depth = w.in_channels;
    auto* logits = static_cast<float*>(band_.get_data_handle());
    for (int y0 = 0; y0 < h8; y0 += band_rows_) {
      const int rows = std::min(band_rows_, h8 - y0);
      const int pixels = rows * w8;
      matmul(pass.stream,
             {features.data.data() + static_cast<std::size_t>(y0) * w8 * features.c, pixels, depth, features.c},
             {w.weight.data(), kLogits, depth, depth}, logits, kLogits, {.transpose_b = true, .bias = w.bias.data()});
      pass.stream.wait();
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
      exp_in_place(pass.stream, logits, static_cast<std::size_t>(pixels) * kLogits);
      pass.stream.wait();
#pragma omp parallel for
      for (int p = 0; p < pixels; ++p) {
        const int y = y0 + p / w8, x = p % w8;
        // The 3×3 neighbourhood of the coarse flow, zero outside; k = 3 * ky + kx.
        float nu[kNeighbours], nv[kNeighbours];
        for (int k = 0; k < kNeighbours; ++k) {
          const int yy = y + k / 3 - 1, xx = x + k % 3 - 1;
          const bool inside = yy >= 0 && yy < h8 && xx >= 0 && xx < w8;
          nu[k] = inside ? flow8.pixel(yy, xx)[op_.flow.channel] : 0.f;
          nv[k] = inside ? flow8.pixel(yy, xx)[op_.flow.channel + 1] : 0.f;
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
          float* out = flow.pixel(y * kFactor + a, x * kFactor) + op_.out.channel;
          for (int b = 0; b < kFactor; ++b) {
            out[flow.c * b] = kFactor * u[a * kFactor + b] / sum[a * kFactor + b];
            out[flow.c * b + 1] = kFactor * v[a * kFactor + b] / sum[a * kFactor + b];
          }
        }
      }
    }
  }

 private:
  const graph::ConvexUpsample op_;
  const graph::Conv2d<HostTensor> head_;
  int band_rows_ = 1;
  dnnl::memory band_;
};

}  // namespace

std::unique_ptr<CpuOp> build_op(const graph::ConvexUpsample& op, OpBuild& b) {
  if (!b.fused_mask) throw std::logic_error("the CPU's convex upsampling computes its mask itself");
  return std::make_unique<ConvexUpsampleOp>(op, b);
}

}  // namespace neuflow::model
