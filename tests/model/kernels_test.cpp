// Optimized kernels against naive versions written straight from the network doc.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <sstream>
#include <tuple>

#include "dnnl/context.hpp"
#include "dnnl/conv_op.hpp"
#include "kernels/local_correlation.hpp"
#include "tensor.hpp"

namespace neuflow::model {
namespace {

template <typename Floats>  // std::vector<float> or a tensor's TensorData
void fill_random(Floats& v, std::mt19937& rng, float scale = 1.f) {
  std::normal_distribution<float> d(0.f, scale);
  for (float& x : v) x = d(rng);
}

// The reference's way: the all-pairs volume C[p, q] = <F0(p), F1(q)> / sqrt(C), sampled
// bilinearly (corner-aligned, zero outside) at p + flow + (dx, dy).
float naive_corr(const Tensor& f0, const Tensor& f1, const Tensor& flow, int y, int x, int dx, int dy) {
  const auto volume = [&](int qy, int qx) -> double {
    if (qx < 0 || qy < 0 || qx >= f1.w || qy >= f1.h) return 0.0;
    double s = 0;
    for (int c = 0; c < f0.c; ++c) s += static_cast<double>(f0.pixel(y, x)[c]) * f1.pixel(qy, qx)[c];
    return s / std::sqrt(static_cast<double>(f0.c));
  };
  const double px = static_cast<float>(x) + flow.pixel(y, x)[0] + static_cast<float>(dx);
  const double py = static_cast<float>(y) + flow.pixel(y, x)[1] + static_cast<float>(dy);
  const int x0 = static_cast<int>(std::floor(px)), y0 = static_cast<int>(std::floor(py));
  const double ax = px - x0, ay = py - y0;
  return static_cast<float>((1 - ax) * (1 - ay) * volume(y0, x0) + ax * (1 - ay) * volume(y0, x0 + 1) +
                            (1 - ax) * ay * volume(y0 + 1, x0) + ax * ay * volume(y0 + 1, x0 + 1));
}

TEST(LocalCorrelation, MatchesSamplingTheAllPairsVolume) {
  std::mt19937 rng(7);
  const int h = 9, w = 13, c = 128;
  Tensor f0(h, w, c), f1(h, w, c), flow(h, w, 2), out(h, w, 81 + 5);
  fill_random(f0.data, rng);
  fill_random(f1.data, rng);
  fill_random(flow.data, rng, 3.f);  // fractional flows, many windows crossing the border
  flow.pixel(0, 0)[0] = 1e9f;        // far outside: all zero
  local_correlation(all_channels(f0), all_channels(f1), flow, out, 5);
  double max_err = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int i = 0; i < 9; ++i) {
        for (int j = 0; j < 9; ++j) {
          const float expected = (y == 0 && x == 0) ? 0.f : naive_corr(f0, f1, flow, y, x, i - 4, j - 4);
          const float got = out.pixel(y, x)[5 + i * 9 + j];
          max_err = std::max(max_err, static_cast<double>(std::fabs(expected - got)));
          ASSERT_NEAR(got, expected, 1e-4) << "pixel (" << x << ", " << y << ") dx " << i - 4 << " dy " << j - 4
                                           << " flow (" << flow.pixel(y, x)[0] << ", " << flow.pixel(y, x)[1] << ")";
        }
      }
    }
  }
  RecordProperty("max_err", std::to_string(max_err));
}

float naive_conv(const ConvWeights& w, const Tensor& in, int stride, int pad, int oy, int ox, int oc) {
  double s = w.bias.empty() ? 0.0 : w.bias[oc];
  for (int ic = 0; ic < w.in_channels; ++ic)
    for (int ky = 0; ky < w.kernel_h; ++ky)
      for (int kx = 0; kx < w.kernel_w; ++kx) {
        const int iy = oy * stride - pad + ky, ix = ox * stride - pad + kx;
        if (iy < 0 || ix < 0 || iy >= in.h || ix >= in.w) continue;
        s += static_cast<double>(
                 w.weight[((static_cast<std::size_t>(oc) * w.in_channels + ic) * w.kernel_h + ky) * w.kernel_w + kx]) *
             in.pixel(iy, ix)[ic];
      }
  return static_cast<float>(s);
}

struct ConvCase {
  int in_c, out_c, k, stride, pad, h, w;
  bool bias;
  Activation act;
  bool accumulate;
};

class ConvOpTest : public ::testing::TestWithParam<std::tuple<ConvCase, CpuConvolution>> {};

// Each way of computing a convolution: oneDNN's direct one and (for the layers it takes)
// Winograd F(4×4, 3×3) or F(6×6, 3×3); each against the definition in double.
TEST_P(ConvOpTest, MatchesNaiveConvolution) {
  const ConvCase p = std::get<0>(GetParam());
  const CpuConvolution algorithm = std::get<1>(GetParam());
  std::mt19937 rng(11);
  ConvWeights w{p.out_c, p.in_c, p.k, p.k, std::vector<float>(static_cast<std::size_t>(p.out_c) * p.in_c * p.k * p.k),
                {}};
  fill_random(w.weight, rng, 0.1f);
  if (p.bias) {
    w.bias.resize(p.out_c);
    fill_random(w.bias, rng);
  }
  Tensor in(p.h, p.w, p.in_c), out, addend_t;
  fill_random(in.data, rng);
  dnnl::stream stream(cpu_engine());
  PlanContext context{{}, algorithm};
  ConvOp op(w, {p.stride, p.pad, p.act, p.accumulate}, nhwc_desc(p.h, p.w, p.in_c), context);
  context.arena.finalize();
  // Winograd takes stride-1 3×3 layers, and 3s-wide stride-s ones with padding s on a
  // multiple of 8 channels and an input of whole phases (by space-to-depth).
  const bool winograd_shape = p.k == 3 * p.stride && p.pad == p.stride &&
                              (p.stride == 1 || (p.in_c % 8 == 0 && p.h % p.stride == 0 && p.w % p.stride == 0));
  ASSERT_EQ(op.is_winograd(), algorithm != CpuConvolution::direct && winograd_shape);
  std::optional<dnnl::memory> addend;
  if (p.accumulate) {
    addend_t.resize(op.out_h(), op.out_w(), p.out_c);
    fill_random(addend_t.data, rng);
    addend = dnnl::memory(op.output_desc(), cpu_engine());
    dnnl::memory src = wrap_nhwc(addend_t);
    dnnl::reorder(src, *addend).execute(stream, src, *addend);
  }
  op.run_to_nhwc(stream, wrap_nhwc(in), out, addend ? &*addend : nullptr);
  stream.wait();
  ASSERT_EQ(out.h, (p.h + 2 * p.pad - p.k) / p.stride + 1);
  for (int y = 0; y < out.h; ++y)
    for (int x = 0; x < out.w; ++x)
      for (int c = 0; c < p.out_c; ++c) {
        float e = naive_conv(w, in, p.stride, p.pad, y, x, c);
        if (p.accumulate) e += addend_t.pixel(y, x)[c];
        switch (p.act) {
          case Activation::none: break;
          case Activation::relu: e = std::max(e, 0.f); break;
          case Activation::leaky_relu: e = e < 0 ? 0.1f * e : e; break;
          case Activation::gelu: e = 0.5f * e * (1.f + std::erf(e / std::sqrt(2.f))); break;
        }
        ASSERT_NEAR(out.pixel(y, x)[c], e, 1e-4f * (1.f + std::fabs(e)))
            << "in_c " << p.in_c << " out_c " << p.out_c << " k " << p.k << " stride " << p.stride << " pad " << p.pad
            << " at (" << x << ", " << y << ", " << c << ")";
      }
}

// The shapes the network uses: the backbone's strided first convolutions on 3 channels,
// channel counts that are not multiples of 8, fused activations and the accumulate path.
INSTANTIATE_TEST_SUITE_P(
    NetworkShapes, ConvOpTest,
    ::testing::Combine(::testing::Values(ConvCase{3, 16, 8, 4, 2, 24, 32, false, Activation::leaky_relu, false},
                                         ConvCase{3, 16, 6, 2, 2, 12, 16, false, Activation::leaky_relu, false},
                                         ConvCase{3, 8, 8, 8, 0, 16, 24, false, Activation::leaky_relu, false},
                                         ConvCase{147, 24, 3, 1, 1, 5, 7, false, Activation::leaky_relu, true},
                                         ConvCase{96, 66, 3, 1, 1, 6, 5, true, Activation::none, false},
                                         ConvCase{130, 32, 3, 1, 1, 4, 6, true, Activation::relu, false},
                                         ConvCase{64, 40, 1, 1, 0, 4, 4, true, Activation::none, false},
                                         ConvCase{40, 24, 3, 1, 1, 5, 5, false, Activation::gelu, false},
                                         // Several tiles, borders cut inside a tile, channels past one block.
                                         ConvCase{20, 36, 3, 1, 1, 13, 18, true, Activation::leaky_relu, true},
                                         // 6×6 stride 2 (block_8_16): by space-to-depth on 16 channels
                                         // (a 7×9 view: border tiles only; 15×17: whole ones too),
                                         // and on an odd-sized input, directly.
                                         ConvCase{16, 24, 6, 2, 2, 14, 18, true, Activation::leaky_relu, false},
                                         ConvCase{16, 24, 6, 2, 2, 30, 34, true, Activation::leaky_relu, false},
                                         ConvCase{16, 24, 6, 2, 2, 13, 18, true, Activation::leaky_relu, false}),
                       ::testing::Values(CpuConvolution::direct, CpuConvolution::winograd4,
                                         CpuConvolution::winograd6)));

// The arena reuses a released buffer's bytes for buffers made afterwards in the same region,
// never lets two buffers alive at the same time overlap, and places the largest first: here a
// buffer made after a small one is released does not fit that one's bytes, and placing buffers
// as they came would have put it after both (16 KiB), where largest-first needs 12 KiB.
TEST(ScratchArena, LiveBuffersNeverOverlapAndTheLargestArePlacedFirst) {
  const auto floats = [](int n) {
    return dnnl::memory::desc({n}, dnnl::memory::data_type::f32, dnnl::memory::format_tag::a);
  };
  ScratchArena arena;
  const dnnl::memory a = arena.make(floats(1024)), b = arena.make(floats(1024));
  arena.release(a);
  const dnnl::memory c = arena.make(floats(2048));   // alive with b, not with a
  EXPECT_THROW(arena.release(a), std::logic_error);  // twice
  Tensor t;
  arena.make_tensor(t, 2, 4, 8);  // 256 bytes, alive with b and c
  arena.next_region("second");
  EXPECT_THROW(arena.release(c), std::logic_error);  // of an earlier region
  const dnnl::memory f = arena.make(floats(4096));   // overlaps the first region: allowed
  arena.finalize();
  const auto at = [](const dnnl::memory& m) { return static_cast<const char*>(m.get_data_handle()); };
  EXPECT_EQ(at(c), at(a));         // largest first, at 0; a (not alive with it) there too
  EXPECT_EQ(at(b), at(c) + 8192);  // b lives with c
  EXPECT_EQ(reinterpret_cast<const char*>(t.data.data()), at(b) + 4096);
  EXPECT_TRUE(t.data.is_view());
  EXPECT_EQ(t.data.size(), 64u);
  EXPECT_EQ(at(f), at(a));
  EXPECT_EQ(arena.regions().size(), 2u);
  EXPECT_EQ(arena.regions()[0].bytes, 3 * 4096u + 256u);
  EXPECT_EQ(arena.regions()[1].name, "second");
  EXPECT_EQ(arena.size_bytes(), 16384u);
}

// A tensor of the arena: its copy owns its floats, a move keeps the view, and resizing it to
// its own shape keeps it in the arena.
TEST(ScratchArena, TensorsStayViewsOfTheArenaAndCopiesOwnTheirFloats) {
  ScratchArena arena;
  Tensor t;
  arena.make_tensor(t, 3, 5, 2);
  arena.finalize();
  float* where = t.data.data();
  t.pixel(2, 4)[1] = 7.f;
  Tensor copy = t;
  EXPECT_FALSE(copy.data.is_view());
  EXPECT_NE(copy.data.data(), where);
  EXPECT_EQ(copy.pixel(2, 4)[1], 7.f);
  t.resize(3, 5, 2);
  EXPECT_EQ(t.data.data(), where);
  EXPECT_EQ(t.pixel(2, 4)[1], 0.f);
  Tensor moved = std::move(t);
  EXPECT_EQ(moved.data.data(), where);
  moved.resize(4, 5, 2);  // another size: its own floats, the arena's untouched
  EXPECT_FALSE(moved.data.is_view());
  EXPECT_NE(moved.data.data(), where);
}

}  // namespace
}  // namespace neuflow::model
