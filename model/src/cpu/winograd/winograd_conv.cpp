#include "winograd/winograd_conv.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <stdexcept>

#include "winograd/packed_gemm.hpp"
#include "winograd/winograd_f43.hpp"

namespace neuflow::model {

using namespace winograd;

namespace {

constexpr int kLanes = 8;  // channels per block of the nChw8c layout

int round_up(int v, int m) { return (v + m - 1) / m * m; }
int divide_up(int v, int m) { return (v + m - 1) / m; }

// The transformed inputs of one block should stay in the core's L2 (512 KiB on Zen 3) while
// the 36 products read them, with room for the filters' panels and the products.
constexpr std::size_t kBlockInputBytes = 256 * 1024;
constexpr int kMaxBlockTiles = 96;

Float8 activate(Float8 v, Activation a) {
  switch (a) {
    case Activation::none: return v;
    case Activation::leaky_relu: return v > 0.f ? v : 0.1f * v;
    case Activation::relu: return v > 0.f ? v : Float8{};
    case Activation::gelu:
      for (int i = 0; i < kLanes; ++i) v[i] = 0.5f * v[i] * (1.f + std::erf(v[i] * 0.70710678118654752f));
      return v;
  }
  return v;
}

}  // namespace

bool WinogradConv::handles(const ConvWeights& w, const ConvParams& p) {
  return w.kernel_h == 3 && w.kernel_w == 3 && p.stride == 1 && p.pad == 1;
}

WinogradConv::WinogradConv(const ConvWeights& w, const ConvParams& p, int height, int width, ScratchArena& arena)
    : height_(height),
      width_(width),
      in_channels_(round_up(w.in_channels, kLanes)),
      out_channels_(round_up(w.out_channels, kLanes)),
      gemm_columns_(round_up(w.out_channels, kGemmPanel)),
      activation_(p.activation),
      accumulate_(p.accumulate),
      tiles_x_(divide_up(width, kOutputTile)),
      tiles_(divide_up(height, kOutputTile) * tiles_x_),
      arena_(&arena) {
  if (!handles(w, p)) throw std::logic_error("WinogradConv: not a stride-1, pad-1 3x3 convolution");

  // Blocks of tiles: as many tiles as keep a block's inputs in L2, and a multiple of the
  // thread count of blocks so no thread waits for another's last block.
  threads_ = std::max(1, omp_get_max_threads());
  const auto fit = static_cast<int>(kBlockInputBytes / (sizeof(float) * kPoints * in_channels_));
  const int most = std::clamp(fit / kGemmRows * kGemmRows, kGemmRows, kMaxBlockTiles);
  blocks_ = round_up(divide_up(tiles_, most), threads_);
  block_tiles_ = round_up(divide_up(tiles_, blocks_), kGemmRows);
  blocks_ = divide_up(tiles_, block_tiles_);
  thread_floats_ = static_cast<std::size_t>(kPoints) * block_tiles_ * (in_channels_ + gemm_columns_);
  arena.reserve_workspace(sizeof(float) * thread_floats_ * static_cast<std::size_t>(threads_));

  // Filters: G g Gᵀ for every (output, input) pair, packed as the GEMM reads them.
  const int panels = gemm_columns_ / kGemmPanel;
  filters_.assign(static_cast<std::size_t>(kPoints) * gemm_columns_ * in_channels_, 0.f);
  float points[kPoints];
  for (int o = 0; o < w.out_channels; ++o) {
    for (int c = 0; c < w.in_channels; ++c) {
      transform_filter(w.weight.data() + (static_cast<std::size_t>(o) * w.in_channels + c) * 9, points);
      for (int xi = 0; xi < kPoints; ++xi) {
        const std::size_t panel = static_cast<std::size_t>(xi) * panels + o / kGemmPanel;
        filters_[(panel * in_channels_ + c) * kGemmPanel + o % kGemmPanel] = points[xi];
      }
    }
  }
  bias_.assign(static_cast<std::size_t>(gemm_columns_), 0.f);
  std::copy(w.bias.begin(), w.bias.end(), bias_.begin());
}

void WinogradConv::transform_inputs(const float* input, int first, int count, float* points) const {
  const std::size_t point_stride = static_cast<std::size_t>(block_tiles_) * in_channels_;
  const std::size_t plane = static_cast<std::size_t>(height_) * width_ * kLanes;
  Float8 d[kPoints], v[kPoints];
  for (int t = 0; t < count; ++t) {
    const int tile = first + t;
    const int y0 = tile / tiles_x_ * kOutputTile - 1;
    const int x0 = tile % tiles_x_ * kOutputTile - 1;
    const bool inside = y0 >= 0 && x0 >= 0 && y0 + kInputTile <= height_ && x0 + kInputTile <= width_;
    for (int cb = 0; cb < in_channels_ / kLanes; ++cb) {
      const float* src = input + cb * plane;
      for (int i = 0; i < kInputTile; ++i) {
        const int y = y0 + i;
        for (int j = 0; j < kInputTile; ++j) {
          const int x = x0 + j;
          const bool here = inside || (y >= 0 && y < height_ && x >= 0 && x < width_);
          d[i * kInputTile + j] = here ? load8(src + (static_cast<std::size_t>(y) * width_ + x) * kLanes) : Float8{};
        }
      }
      transform_input(d, v);
      float* dst = points + static_cast<std::size_t>(t) * in_channels_ + cb * kLanes;
      for (int xi = 0; xi < kPoints; ++xi) store8(dst + xi * point_stride, v[xi]);
    }
  }
  // The GEMM takes whole groups of rows: tiles past the image's last one are zeros.
  for (int t = count; t < round_up(count, kGemmRows); ++t) {
    for (int xi = 0; xi < kPoints; ++xi) {
      std::fill_n(points + xi * point_stride + static_cast<std::size_t>(t) * in_channels_, in_channels_, 0.f);
    }
  }
}

void WinogradConv::transform_outputs(const float* products, int first, int count, const float* addend,
                                     float* output) const {
  const std::size_t point_stride = static_cast<std::size_t>(block_tiles_) * gemm_columns_;
  const std::size_t plane = static_cast<std::size_t>(height_) * width_ * kLanes;
  Float8 m[kPoints], o[kOutputTile * kOutputTile];
  for (int t = 0; t < count; ++t) {
    const int tile = first + t;
    const int y0 = tile / tiles_x_ * kOutputTile;
    const int x0 = tile % tiles_x_ * kOutputTile;
    const int rows = std::min(kOutputTile, height_ - y0);
    const int cols = std::min(kOutputTile, width_ - x0);
    for (int kb = 0; kb < out_channels_ / kLanes; ++kb) {
      const float* src = products + static_cast<std::size_t>(t) * gemm_columns_ + kb * kLanes;
      for (int xi = 0; xi < kPoints; ++xi) m[xi] = load8(src + xi * point_stride);
      transform_output(m, o);
      const Float8 bias = load8(bias_.data() + kb * kLanes);
      for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < cols; ++j) {
          const std::size_t at = kb * plane + (static_cast<std::size_t>(y0 + i) * width_ + x0 + j) * kLanes;
          Float8 value = o[i * kOutputTile + j] + bias;
          if (addend) value += load8(addend + at);
          store8(output + at, activate(value, activation_));
        }
      }
    }
  }
}

void WinogradConv::run(const float* input, const float* addend, float* output) const {
  if (accumulate_ != (addend != nullptr)) throw std::logic_error("WinogradConv: addend given iff accumulate");
  auto* workspace = reinterpret_cast<float*>(arena_->workspace());
  const int threads = std::min(threads_, std::max(1, omp_get_max_threads()));
  const std::size_t gemm_rows_stride = static_cast<std::size_t>(block_tiles_);
#pragma omp parallel num_threads(threads)
  {
    float* points = workspace + static_cast<std::size_t>(omp_get_thread_num()) * thread_floats_;
    float* products = points + kPoints * gemm_rows_stride * in_channels_;
#pragma omp for schedule(static)
    for (int b = 0; b < blocks_; ++b) {
      const int first = b * block_tiles_;
      const int count = std::min(block_tiles_, tiles_ - first);
      const int rows = round_up(count, kGemmRows);
      transform_inputs(input, first, count, points);
      for (int xi = 0; xi < kPoints; ++xi) {
        packed_gemm(points + xi * gemm_rows_stride * in_channels_,
                    filters_.data() + static_cast<std::size_t>(xi) * gemm_columns_ * in_channels_,
                    products + xi * gemm_rows_stride * gemm_columns_, rows, in_channels_, gemm_columns_);
      }
      transform_outputs(products, first, count, addend, output);
    }
  }
}

}  // namespace neuflow::model
