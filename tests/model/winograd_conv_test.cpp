// Winograd F(4×4, 3×3) and F(6×6, 3×3) against oneDNN's direct convolution at every layer of
// NeuFlow-V2 it computes (the stride-1 3×3 ones, and the 6×6 stride-2 one by space-to-depth),
// at the shapes a 768×432 and a 1024×448 model size give them (1/16 is 27 rows and 1/8 is 56
// rows: tiles cut by the border), on random data; and each product kernel this CPU runs
// against the portable one.
//
// The bound: the largest difference from the direct result is at most 1e-5 (F(4×4)) or 2e-5
// (F(6×6), whose transform coefficients reach 32) of the sum of |weight × input| over the
// output's receptive field (the scale of what rounding either way can change). Measured on
// these layers (AVX-512 host, 2026-12-03): F(4×4) 1.8e-6 to 4.4e-6, F(6×6) 3.3e-6 to 7.3e-6.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "dnnl/context.hpp"
#include "dnnl/conv_op.hpp"
#include "neuflow/model/architecture.hpp"
#include "winograd/packed_gemm.hpp"

namespace neuflow::model {
namespace {

using tag = dnnl::memory::format_tag;

struct LayerShape {
  std::string name;
  int in, out, scale;  // scale: the output's
  int stride = 1;      // kernel 3·stride, padding stride
};

// Every layer Winograd computes: the stride-1 3×3 ones and the 6×6 stride-2 one on 192
// channels (block_8_16.conv1, by space-to-depth).
std::vector<LayerShape> winograd_layers() {
  std::vector<LayerShape> layers;
  for (const auto& l : neuflow_v2_layers()) {
    if (l.kind == LayerKind::conv && l.kernel == 3) layers.push_back({l.name, l.in, l.out, l.scale});
    if (l.kind == LayerKind::conv && l.kernel == 6 && l.in % 8 == 0)
      layers.push_back({l.name, l.in, l.out, l.scale, 2});
  }
  // The refinements' first convolution runs split: per-iteration inputs and per-pair constants.
  for (const int scale : {8, 16}) {
    layers.push_back({"refine_s" + std::to_string(scale) + ".conv1 per iteration", 147, 128, scale});
    layers.push_back({"refine_s" + std::to_string(scale) + ".conv1 per pair", 65, 128, scale});
  }
  return layers;
}

// Runs one convolution on an NHWC input and returns its NHWC output.
Tensor convolve(const ConvWeights& w, const Tensor& input, CpuConvolution choice, bool& used_winograd) {
  PlanContext context{{}, choice};
  const int stride = w.kernel_h / 3;
  ConvOp op(w, {stride, stride, Activation::none}, nhwc_desc(input.h, input.w, input.c), context);
  context.arena.finalize();
  used_winograd = op.is_winograd();
  dnnl::stream stream(cpu_engine());
  Tensor in = input, out;
  op.run_to_nhwc(stream, wrap_nhwc(in), out);
  stream.wait();
  return out;
}

class WinogradTileForm : public ::testing::TestWithParam<CpuConvolution> {};

TEST_P(WinogradTileForm, MatchesDirectAtEveryNetworkLayer) {
  const double bound = GetParam() == CpuConvolution::winograd6 ? 2e-5 : 1e-5;
  std::mt19937 rng(7);
  std::normal_distribution<float> normal(0.f, 1.f);
  for (const auto& [width, height] : {std::pair{768, 432}, std::pair{1024, 448}}) {
    for (const auto& layer : winograd_layers()) {
      SCOPED_TRACE(layer.name + " at " + std::to_string(width) + "x" + std::to_string(height));
      const int h = height / layer.scale * layer.stride, w = width / layer.scale * layer.stride;  // the input's
      const int k = 3 * layer.stride;
      ConvWeights weights{layer.out,
                          layer.in,
                          k,
                          k,
                          std::vector<float>(static_cast<std::size_t>(layer.out) * layer.in * k * k),
                          std::vector<float>(static_cast<std::size_t>(layer.out))};
      const float scale = 1.f / std::sqrt(static_cast<float>(k * k * layer.in));
      for (auto& v : weights.weight) v = scale * normal(rng);
      for (auto& v : weights.bias) v = 0.1f * normal(rng);
      Tensor input(h, w, layer.in);
      for (auto& v : input.data) v = normal(rng);

      bool direct_winograd = true, winograd_winograd = false;
      const Tensor direct = convolve(weights, input, CpuConvolution::direct, direct_winograd);
      const Tensor winograd = convolve(weights, input, GetParam(), winograd_winograd);
      ASSERT_FALSE(direct_winograd);
      ASSERT_TRUE(winograd_winograd);
      ASSERT_EQ(winograd.data.size(), direct.data.size());

      // The receptive field's |weight × input| sum at every output: the direct convolution of
      // |weights| over |input|, plus |bias|.
      ConvWeights magnitude_weights = weights;
      for (auto& v : magnitude_weights.weight) v = std::fabs(v);
      for (auto& v : magnitude_weights.bias) v = std::fabs(v);
      Tensor magnitude_input = input;
      for (auto& v : magnitude_input.data) v = std::fabs(v);
      bool unused = false;
      const Tensor magnitude = convolve(magnitude_weights, magnitude_input, CpuConvolution::direct, unused);
      double worst = 0;
      for (std::size_t i = 0; i < direct.data.size(); ++i) {
        worst = std::max(worst, std::fabs(static_cast<double>(winograd.data[i]) - direct.data[i]) / magnitude.data[i]);
      }
      EXPECT_LE(worst, bound) << "largest difference relative to the receptive field's magnitude";
      char recorded[32];
      std::snprintf(recorded, sizeof recorded, "%.2e", worst);
      RecordProperty(layer.name + " " + std::to_string(width) + "x" + std::to_string(height), recorded);
    }
  }
}

// Winograd reads and writes NHWC, nChw8c and nChw16c in place; channel counts that are not
// multiples of 8 or 16 leave partial groups at the end of each pixel (NHWC) or padding
// channels (blocked, which must be written as zeros). Twice: a 3×3 layer, and a 6×6 stride-2
// one by space-to-depth on 24 channels (eight-channel groups straddle a 16-channel block; a
// 15×17 view, so whole tiles as well as border ones).
TEST_P(WinogradTileForm, EveryLayoutInAndOutGivesTheDirectResult) {
  struct Shape {
    int in, out, stride, h, w;  // h, w: the input's
  };
  for (const Shape shape : {Shape{147, 66, 1, 13, 18}, Shape{24, 40, 2, 30, 34}}) {
    SCOPED_TRACE("stride " + std::to_string(shape.stride));
    const int k = 3 * shape.stride, oh = shape.h / shape.stride, ow = shape.w / shape.stride;
    std::mt19937 rng(11);
    std::normal_distribution<float> normal(0.f, 1.f);
    ConvWeights weights{shape.out,
                        shape.in,
                        k,
                        k,
                        std::vector<float>(static_cast<std::size_t>(shape.out) * shape.in * k * k),
                        std::vector<float>(static_cast<std::size_t>(shape.out))};
    for (auto& v : weights.weight) v = normal(rng) / static_cast<float>(4 * k * k);
    for (auto& v : weights.bias) v = normal(rng);
    Tensor input(shape.h, shape.w, shape.in);
    for (auto& v : input.data) v = normal(rng);
    bool used = false;
    const Tensor direct = convolve(weights, input, CpuConvolution::direct, used);
    dnnl::stream stream(cpu_engine());
    for (const tag in_tag : {tag::nhwc, tag::nChw8c, tag::nChw16c}) {
      for (const tag out_tag : {tag::nhwc, tag::nChw8c, tag::nChw16c}) {
        SCOPED_TRACE("input " + std::to_string(static_cast<int>(in_tag)) + ", output " +
                     std::to_string(static_cast<int>(out_tag)));
        const dnnl::memory::desc in_desc({1, shape.in, shape.h, shape.w}, dnnl::memory::data_type::f32, in_tag);
        const dnnl::memory::desc out_desc({1, shape.out, oh, ow}, dnnl::memory::data_type::f32, out_tag);
        PlanContext context{{}, GetParam()};
        ConvOp op(weights, {shape.stride, shape.stride, Activation::leaky_relu}, in_desc, context, out_desc);
        context.arena.finalize();
        ASSERT_TRUE(op.is_winograd());
        // The output's padding channels start as garbage: Winograd must leave them zero.
        std::memset(op.output().get_data_handle(), 0x7f, out_desc.get_size());
        Tensor in_copy = input;
        dnnl::memory nhwc_in = wrap_nhwc(in_copy), laid_out(in_desc, cpu_engine());
        dnnl::reorder(nhwc_in, laid_out).execute(stream, nhwc_in, laid_out);
        Tensor out;
        op.run_to_nhwc(stream, laid_out, out);
        stream.wait();
        ASSERT_EQ(out.data.size(), direct.data.size());
        for (std::size_t i = 0; i < direct.data.size(); ++i) {
          const float d = direct.data[i] < 0 ? 0.1f * direct.data[i] : direct.data[i];
          ASSERT_NEAR(out.data[i], d, 1e-4f * (1.f + std::fabs(d))) << "at " << i;
        }
        const int block = out_tag == tag::nChw16c ? 16 : 8;
        if (out_tag != tag::nhwc && shape.out % block != 0) {
          const auto* raw = static_cast<const float*>(op.output().get_data_handle());
          const std::size_t last_plane = static_cast<std::size_t>(shape.out / block) * oh * ow * block;
          for (int p = 0; p < oh * ow; ++p) {
            for (int c = shape.out % block; c < block; ++c) {
              ASSERT_EQ(raw[last_plane + p * block + c], 0.f) << "padding channel";
            }
          }
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(WinogradConv, WinogradTileForm,
                         ::testing::Values(CpuConvolution::winograd4, CpuConvolution::winograd6),
                         [](const auto& p) { return std::string(cpu_convolution_name(p.param)); });

TEST(WinogradGemm, EveryKernelMatchesThePortableOne) {
  int count = 0;
  const winograd::GemmKernel* const* kernels = winograd::gemm_kernels(count);
  ASSERT_GE(count, 1);
  const winograd::GemmKernel& portable = *kernels[count - 1];
  ASSERT_STREQ(portable.name, "portable");
  std::mt19937 rng(9);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  constexpr int kDepth = 152, kColumns = 96, kRows = 48;  // multiples of every kernel's rows and panel
  std::vector<float> a(static_cast<std::size_t>(kRows) * kDepth), b(static_cast<std::size_t>(kDepth) * kColumns);
  for (auto& v : a) v = u(rng);
  for (auto& v : b) v = u(rng);
  // The reference in plain row-major B: C[r][j] = Σ_k A[r][k] B[k][j].
  std::vector<double> expected(static_cast<std::size_t>(kRows) * kColumns, 0.0);
  for (int r = 0; r < kRows; ++r)
    for (int k = 0; k < kDepth; ++k)
      for (int j = 0; j < kColumns; ++j)
        expected[r * kColumns + j] += static_cast<double>(a[r * kDepth + k]) * b[k * kColumns + j];
  for (int i = 0; i < count; ++i) {
    const auto& kernel = *kernels[i];
    SCOPED_TRACE(kernel.name);
    ASSERT_EQ(kRows % kernel.rows, 0);
    ASSERT_EQ(kColumns % kernel.panel, 0);
    std::vector<float> packed(b.size());
    for (int k = 0; k < kDepth; ++k)
      for (int j = 0; j < kColumns; ++j)
        packed[(static_cast<std::size_t>(j / kernel.panel) * kDepth + k) * kernel.panel + j % kernel.panel] =
            b[k * kColumns + j];
    std::vector<float> c(static_cast<std::size_t>(kRows) * kColumns, -1.f);
    kernel.run(a.data(), packed.data(), c.data(), kRows, kDepth, kColumns);
    for (std::size_t n = 0; n < c.size(); ++n) ASSERT_NEAR(c[n], expected[n], 1e-4) << "at " << n;
  }
}

}  // namespace
}  // namespace neuflow::model
