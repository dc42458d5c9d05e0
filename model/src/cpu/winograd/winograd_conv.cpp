#include "winograd/winograd_conv.hpp"

#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <map>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "winograd/packed_gemm.hpp"
#include "winograd/winograd_f43.hpp"
#include "winograd/winograd_f63.hpp"
#include "winograd/winograd_tile.hpp"

namespace neuflow::model {

using namespace winograd;

namespace {

constexpr int kLanes = 8;  // channels per block of the nChw8c layout

int round_up(int v, int m) { return (v + m - 1) / m * m; }

// The floats between consecutive points of a block's inputs or products: the 36 points of a
// tile are read (or written) together, and at a stride that is a multiple of 4 KiB they would
// all fall into the same L1 set and evict one another; one cache line more spreads them.
std::size_t point_stride_for(int tiles, int channels) {
  constexpr int kPage = 1024, kLine = 16;  // floats
  return static_cast<std::size_t>(round_up(tiles * channels, kPage) + kLine);
}
int divide_up(int v, int m) { return (v + m - 1) / m; }

// A block's tiles: a thread's whole workspace (36 or 64 points of inputs and products) stays
// within half of its core's L2 (or is one group of the kernel's rows of tiles, where even that
// is larger: the widest layers), so what the input transform writes is still there when the
// products read it, and what they write is still there for the output transform; the
// filters' panels stream through the rest. (A core's L2 as the C library reports it; with two
// hardware threads on a core each has less.) Measured with neuflow-bench-conv on a 1 MiB-L2 core
// (docs/benchmarks.md): a 6 MiB workspace (blocks of ~170 tiles, living in L3) made the
// network's Winograd layers 2.3–2.5× the direct ones, a 512 KiB one 2.8–3.0×; smaller
// blocks read the filters more often, but those reads stream from L2 and L3 at the
// micro-kernel's pace. One point's inputs never exceed a quarter of the L2.
constexpr std::size_t kFallbackL2Bytes = 1024 * 1024;  // where the C library cannot tell
constexpr int kMaxBlockTiles = 480;

std::size_t l2_bytes() {
  static const std::size_t bytes = [] {
    const long reported = sysconf(_SC_LEVEL2_CACHE_SIZE);  // 0 or -1 where unknown (e.g. some aarch64)
    return reported >= 256 * 1024 ? static_cast<std::size_t>(reported) : kFallbackL2Bytes;
  }();
  return bytes;
}

template <Activation A>
Float8 activate(Float8 v) {
  if constexpr (A == Activation::leaky_relu) return v > 0.f ? v : 0.1f * v;
  if constexpr (A == Activation::relu) return v > 0.f ? v : Float8{};
  if constexpr (A == Activation::gelu) {
    for (int i = 0; i < kLanes; ++i) v[i] = 0.5f * v[i] * (1.f + std::erf(v[i] * 0.70710678118654752f));
  }
  return v;
}

// G g Gᵀ for every (output, input) pair of `w`, packed as `kernel` reads them.
template <typename T>
std::vector<float> transform_filters(const ConvWeights& w, const GemmKernel& kernel, int depth, int columns) {
  const int panel = kernel.panel;
  const int panels = columns / panel;
  std::vector<float> filters(static_cast<std::size_t>(T::kPoints) * columns * depth, 0.f);
  float points[T::kPoints];
  for (int o = 0; o < w.out_channels; ++o) {
    for (int c = 0; c < w.in_channels; ++c) {
      transform_filter<T>(w.weight.data() + (static_cast<std::size_t>(o) * w.in_channels + c) * 9, points);
      for (int xi = 0; xi < T::kPoints; ++xi) {
        const std::size_t at = static_cast<std::size_t>(xi) * panels + o / panel;
        filters[(at * depth + c) * panel + o % panel] = points[xi];
      }
    }
  }
  return filters;
}

// A stride-s convolution whose kernel is 3s wide with padding s is, on the space-to-depth view
// of its input (s² phases × C channels at 1/s the size), a stride-1, pad-1 3×3 one: output
// o reads input rows s·o − s … s·o + 2s − 1, i.e. phase rows o − 1, o, o + 1. Its 3×3 filter
// for (out, phase (ry, rx), channel c) is taps (s·ky + ry, s·kx + rx) of the original; view
// channel (ry·s + rx)·C + c.
ConvWeights space_to_depth_filters(const ConvWeights& w, int s) {
  if (s == 1) return w;
  const int c_in = w.in_channels, k = w.kernel_h, depth = c_in * s * s;
  ConvWeights r{w.out_channels, depth, 3, 3, std::vector<float>(static_cast<std::size_t>(w.out_channels) * depth * 9),
                w.bias};
  for (int o = 0; o < w.out_channels; ++o) {
    for (int phase = 0; phase < s * s; ++phase) {
      for (int c = 0; c < c_in; ++c) {
        float* dst = r.weight.data() + (static_cast<std::size_t>(o) * depth + phase * c_in + c) * 9;
        const float* src = w.weight.data() + (static_cast<std::size_t>(o) * c_in + c) * k * k;
        for (int ky = 0; ky < 3; ++ky) {
          for (int kx = 0; kx < 3; ++kx) dst[ky * 3 + kx] = src[(s * ky + phase / s) * k + s * kx + phase % s];
        }
      }
    }
  }
  return r;
}

// FNV-1a over the weights' bytes: with the address, what identifies a layer's weights even if
// another layer's were once at that address.
std::uint64_t fingerprint(const ConvWeights& w) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* bytes = reinterpret_cast<const unsigned char*>(w.weight.data());
  for (std::size_t i = 0; i < w.weight.size() * sizeof(float); ++i) h = (h ^ bytes[i]) * 1099511628211ull;
  return h;
}

// The transformed filters are 4× the size of the 3×3 weights (~114 MB for the network), so
// every session of a model shares them, the way sessions share the model: one copy per
// layer for as long as a plan uses it.
std::shared_ptr<const std::vector<float>> shared_filters(const ConvWeights& w, const GemmKernel& kernel, int depth,
                                                         int columns, WinogradTile tile, int stride) {
  using Key = std::tuple<const float*, std::size_t, std::uint64_t, const GemmKernel*, WinogradTile, int>;
  static std::mutex mutex;
  static std::map<Key, std::weak_ptr<const std::vector<float>>> cache;
  const Key key{w.weight.data(), w.weight.size(), fingerprint(w), &kernel, tile, stride};
  const std::lock_guard lock(mutex);
  std::erase_if(cache, [](const auto& e) { return e.second.expired(); });  // layers no plan uses
  auto& entry = cache[key];
  if (auto filters = entry.lock()) return filters;
  const ConvWeights w3 = space_to_depth_filters(w, stride);
  auto filters = std::make_shared<const std::vector<float>>(tile == WinogradTile::f6x6
                                                                ? transform_filters<F63>(w3, kernel, depth, columns)
                                                                : transform_filters<F43>(w3, kernel, depth, columns));
  entry = filters;
  return filters;
}

int output_tile_of(WinogradTile tile) { return tile == WinogradTile::f6x6 ? F63::kOutputTile : F43::kOutputTile; }
int points_of(WinogradTile tile) { return tile == WinogradTile::f6x6 ? F63::kPoints : F43::kPoints; }

// How a layer's tiles are split into blocks.
struct Blocking {
  int tiles_x, tiles;
  int block_tiles;  // a multiple of the kernel's rows
  int blocks;
};

// Blocks of tiles: as many tiles as keep a thread's workspace in half its L2, and a multiple of
// the thread count of blocks so no thread waits for another's last block. Channels padded as
// the products read them (inputs to 8, outputs to the kernel's panel).
Blocking blocking_for(WinogradTile tile, int in_channels, int gemm_columns, int height, int width, int rows,
                      int threads) {
  Blocking b{};
  b.tiles_x = divide_up(width, output_tile_of(tile));
  b.tiles = divide_up(height, output_tile_of(tile)) * b.tiles_x;
  const auto fit_point = static_cast<int>(l2_bytes() / 4 / (sizeof(float) * in_channels));
  const auto fit_thread =
      static_cast<int>(l2_bytes() / 2 / (sizeof(float) * points_of(tile) * (in_channels + gemm_columns)));
  const int most = std::clamp(std::min(fit_point, fit_thread) / rows * rows, rows, kMaxBlockTiles);
  b.blocks = round_up(divide_up(b.tiles, most), threads);
  b.block_tiles = round_up(divide_up(b.tiles, b.blocks), rows);
  b.blocks = divide_up(b.tiles, b.block_tiles);
  return b;
}

}  // namespace

long WinogradConv::busiest_thread_products(WinogradTile tile, int in_channels, int out_channels, int height,
                                           int width) {
  const GemmKernel& kernel = gemm_kernel();
  const int threads = std::max(1, omp_get_max_threads());
  const Blocking b = blocking_for(tile, round_up(in_channels, kLanes), round_up(out_channels, kernel.panel), height,
                                  width, kernel.rows, threads);
  return static_cast<long>(divide_up(b.blocks, threads)) * b.block_tiles * points_of(tile);
}

WinogradTile WinogradConv::faster_tile(int in_channels, int out_channels, int height, int width) {
  const long f6 = busiest_thread_products(WinogradTile::f6x6, in_channels, out_channels, height, width);
  const long f4 = busiest_thread_products(WinogradTile::f4x4, in_channels, out_channels, height, width);
  return f6 < f4 ? WinogradTile::f6x6 : WinogradTile::f4x4;
}

ChannelPlacement::ChannelPlacement(ChannelLayout layout, int c, int height, int w) : channels(c), width(w) {
  const int lanes = layout == ChannelLayout::blocked16 ? 16 : 8;
  if (layout == ChannelLayout::nhwc) {
    pixel = block = c;
    plane = 0;
  } else {
    pixel = block = lanes;
    plane = static_cast<std::size_t>(height) * w * lanes;
  }
  partial_last_group = layout == ChannelLayout::nhwc && c % kLanes != 0;
}

bool WinogradConv::handles(const ConvWeights& w, const ConvParams& p, int height, int width) {
  if (w.kernel_h != w.kernel_w || w.kernel_h != 3 * p.stride || p.pad != p.stride) return false;
  // A strided one by its space-to-depth view: whole phases, and eight channels of one phase
  // side by side in memory.
  return p.stride == 1 || (w.in_channels % kLanes == 0 && height % p.stride == 0 && width % p.stride == 0);
}

WinogradConv::WinogradConv(const ConvWeights& w, const ConvParams& p, int height, int width, ChannelLayout input_layout,
                           ChannelLayout output_layout, WinogradTile tile, ScratchArena& arena)
    : tile_(tile),
      output_tile_(output_tile_of(tile)),
      points_(points_of(tile)),
      stride_(std::max(p.stride, 1)),  // handles() below rejects what is not 1 or 3s-wide
      height_(height / stride_),
      width_(width / stride_),
      input_(input_layout, w.in_channels, height, width),
      output_(output_layout, w.out_channels, height_, width_),
      in_channels_(round_up(w.in_channels * p.stride * p.stride, kLanes)),
      out_channels_(round_up(w.out_channels, output_layout == ChannelLayout::blocked16 ? 2 * kLanes : kLanes)),
      kernel_(&gemm_kernel()),
      gemm_columns_(round_up(w.out_channels, kernel_->panel)),
      activation_(p.activation),
      accumulate_(p.accumulate) {
  if (!handles(w, p, height, width)) {
    throw std::logic_error("WinogradConv: neither a stride-1, pad-1 3x3 convolution nor one by space-to-depth");
  }
  threads_ = std::max(1, omp_get_max_threads());
  const Blocking b = blocking_for(tile, in_channels_, gemm_columns_, height_, width_, kernel_->rows, threads_);
  tiles_x_ = b.tiles_x;
  tiles_ = b.tiles;
  block_tiles_ = b.block_tiles;
  blocks_ = b.blocks;
  input_stride_ = point_stride_for(block_tiles_, in_channels_);
  product_stride_ = point_stride_for(block_tiles_, gemm_columns_);
  thread_floats_ = points_ * (input_stride_ + product_stride_);
  workspace_ = arena.make(dnnl::memory::desc({static_cast<dnnl::memory::dim>(thread_floats_) * threads_},
                                             dnnl::memory::data_type::f32, dnnl::memory::format_tag::a));

  filters_ = shared_filters(w, *kernel_, in_channels_, gemm_columns_, tile_, stride_);
  bias_.assign(static_cast<std::size_t>(gemm_columns_), 0.f);
  std::copy(w.bias.begin(), w.bias.end(), bias_.begin());
}

template <typename T>
void WinogradConv::transform_inputs(const float* input, int first, int count, float* points) const {
  constexpr int kInputTile = T::kInputTile, kOutputTile = T::kOutputTile, kPoints = T::kPoints;
  const std::size_t point_stride = input_stride_;
  const int groups = in_channels_ / kLanes;
  // Steps between the (space-to-depth) view's pixels: s rows or columns of the input.
  const std::size_t row = static_cast<std::size_t>(width_) * stride_ * stride_ * input_.pixel;
  const std::size_t column = static_cast<std::size_t>(stride_) * input_.pixel;
  Float8 d[kPoints], v[kPoints];
  // Eight channels of one pixel; in NHWC the last group may hold fewer, the rest zeros.
  const auto load_group = [&](int group, std::size_t at) {
    if (input_.partial_last_group && group == groups - 1) {
      float lanes[kLanes] = {};
      std::copy_n(input + at, input_.channels - group * kLanes, lanes);
      return load8(lanes);
    }
    return load8(input + at);
  };
  for (int t = 0; t < count; ++t) {
    const int tile = first + t;
    const int y0 = tile / tiles_x_ * kOutputTile - 1;
    const int x0 = tile % tiles_x_ * kOutputTile - 1;
    const bool inside = y0 >= 0 && x0 >= 0 && y0 + kInputTile <= height_ && x0 + kInputTile <= width_;
    for (int g = 0; g < groups; ++g) {
      // The group's phase (ry, rx) and first channel in the input (all zero at stride 1).
      const int phase = g * kLanes / input_.channels * (stride_ > 1);
      const int c = stride_ > 1 ? g * kLanes % input_.channels : g * kLanes;
      const int ry = phase / stride_, rx = phase % stride_;
      if (inside) {
        const std::size_t corner = input_.at(c, stride_ * y0 + ry, stride_ * x0 + rx);
        for (int i = 0; i < kInputTile; ++i) {
          for (int j = 0; j < kInputTile; ++j) d[i * kInputTile + j] = load_group(g, corner + i * row + j * column);
        }
      } else {  // a border tile: the padding is zeros
        for (int i = 0; i < kInputTile; ++i) {
          const int y = y0 + i;
          for (int j = 0; j < kInputTile; ++j) {
            const int x = x0 + j;
            const bool here = y >= 0 && y < height_ && x >= 0 && x < width_;
            d[i * kInputTile + j] = here ? load_group(g, input_.at(c, stride_ * y + ry, stride_ * x + rx)) : Float8{};
          }
        }
      }
      transform_input<T>(d, v);
      float* dst = points + static_cast<std::size_t>(t) * in_channels_ + g * kLanes;
      for (int xi = 0; xi < kPoints; ++xi) store8(dst + xi * point_stride, v[xi]);
    }
  }
  // The GEMM takes whole groups of rows: tiles past the image's last one are zeros.
  for (int t = count; t < round_up(count, kernel_->rows); ++t) {
    for (int xi = 0; xi < kPoints; ++xi) {
      std::fill_n(points + xi * point_stride + static_cast<std::size_t>(t) * in_channels_, in_channels_, 0.f);
    }
  }
}

template <typename T>
void WinogradConv::transform_outputs(const float* products, int first, int count, const float* addend,
                                     float* output) const {
  switch (activation_) {
    case Activation::none: return transform_outputs_as<T, Activation::none>(products, first, count, addend, output);
    case Activation::leaky_relu:
      return transform_outputs_as<T, Activation::leaky_relu>(products, first, count, addend, output);
    case Activation::relu: return transform_outputs_as<T, Activation::relu>(products, first, count, addend, output);
    case Activation::gelu: return transform_outputs_as<T, Activation::gelu>(products, first, count, addend, output);
  }
}

template <typename T, Activation A>
void WinogradConv::transform_outputs_as(const float* products, int first, int count, const float* addend,
                                        float* output) const {
  constexpr int kOutputTile = T::kOutputTile, kPoints = T::kPoints;
  const std::size_t point_stride = product_stride_;
  const int groups = out_channels_ / kLanes;
  const std::size_t row = static_cast<std::size_t>(width_) * output_.pixel;
  Float8 m[kPoints], o[kOutputTile * kOutputTile];
  for (int t = 0; t < count; ++t) {
    const int tile = first + t;
    const int y0 = tile / tiles_x_ * kOutputTile;
    const int x0 = tile % tiles_x_ * kOutputTile;
    const int rows = std::min(kOutputTile, height_ - y0);
    const int cols = std::min(kOutputTile, width_ - x0);
    for (int g = 0; g < groups; ++g) {
      const float* src = products + static_cast<std::size_t>(t) * gemm_columns_ + g * kLanes;
      for (int xi = 0; xi < kPoints; ++xi) m[xi] = load8(src + xi * point_stride);
      transform_output<T>(m, o);
      const Float8 bias = load8(bias_.data() + g * kLanes);
      // In NHWC the last group may hold fewer than eight channels: only those are written.
      const int lanes = output_.partial_last_group && g == groups - 1 ? output_.channels - g * kLanes : kLanes;
      const std::size_t corner = output_.at(g * kLanes, y0, x0);
      for (int i = 0; i < rows; ++i) {
        for (int j = 0; j < cols; ++j) {
          const std::size_t at = corner + i * row + static_cast<std::size_t>(j) * output_.pixel;
          Float8 value = o[i * kOutputTile + j] + bias;
          if (lanes == kLanes) {
            if (addend) value += load8(addend + at);
            store8(output + at, activate<A>(value));
          } else {
            float partial[kLanes] = {};
            if (addend) std::copy_n(addend + at, lanes, partial);
            store8(partial, activate<A>(value + load8(partial)));
            std::copy_n(partial, lanes, output + at);
          }
        }
      }
    }
  }
}

void WinogradConv::run(const float* input, const float* addend, float* output) const {
  if (accumulate_ != (addend != nullptr)) throw std::logic_error("WinogradConv: addend given iff accumulate");
  if (tile_ == WinogradTile::f6x6) {
    run_as<F63>(input, addend, output);
  } else {
    run_as<F43>(input, addend, output);
  }
}

template <typename T>
void WinogradConv::run_as(const float* input, const float* addend, float* output) const {
  constexpr int kPoints = T::kPoints;
  auto* workspace = static_cast<float*>(workspace_.get_data_handle());
  const int threads = std::min(threads_, std::max(1, omp_get_max_threads()));
#pragma omp parallel num_threads(threads)
  {
    float* points = workspace + static_cast<std::size_t>(omp_get_thread_num()) * thread_floats_;
    float* products = points + kPoints * input_stride_;
#pragma omp for schedule(static)
    for (int b = 0; b < blocks_; ++b) {
      const int first = b * block_tiles_;
      const int count = std::min(block_tiles_, tiles_ - first);
      const int rows = round_up(count, kernel_->rows);
      transform_inputs<T>(input, first, count, points);
      for (int xi = 0; xi < kPoints; ++xi) {
        kernel_->run(points + xi * input_stride_,
                     filters_->data() + static_cast<std::size_t>(xi) * gemm_columns_ * in_channels_,
                     products + xi * product_stride_, rows, in_channels_, gemm_columns_);
      }
      transform_outputs<T>(products, first, count, addend, output);
    }
  }
}

}  // namespace neuflow::model
