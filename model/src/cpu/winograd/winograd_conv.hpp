#pragma once
// A stride-1, pad-1 3×3 convolution (or a stride-s one with a 3s kernel and padding s, by the
// space-to-depth view of its input) by Winograd F(4×4, 3×3) or F(6×6, 3×3) for one input
// size, reading and writing the layouts its neighbours use (NHWC, oneDNN's nChw8c or
// nChw16c), so no reorder sits between it and them. The filters are transformed once here.
// run() splits the output's tiles into blocks, one thread a block: each block's inputs are
// transformed (Bᵀ d B), multiplied by the filters point by point (36 or 64 products of
// tiles × channels), and transformed back (Aᵀ m A) with bias, addend and activation applied
// on the way out, so a block's intermediate data stays in the core's cache.
#include <cstddef>
#include <memory>
#include <vector>

#include "dnnl/conv_params.hpp"
#include "dnnl/scratch_arena.hpp"
#include "weights.hpp"
#include "winograd/packed_gemm.hpp"

namespace neuflow::model {

// How one image's channels are laid out in memory.
enum class ChannelLayout { nhwc, blocked8, blocked16 };  // NHWC, nChw8c, nChw16c

// Where channel c of pixel (y, x) is, in floats from the start, for a layout and a shape.
struct ChannelPlacement {
  ChannelPlacement(ChannelLayout layout, int channels, int height, int width);
  std::size_t at(int c, int y, int x) const {
    return static_cast<std::size_t>(c / block) * plane + (static_cast<std::size_t>(y) * width + x) * pixel +
           static_cast<std::size_t>(c % block);
  }
  int channels;  // real channels (blocked layouts hold zeros up to the block's end)
  int width;
  int pixel;                // floats from one pixel to the next
  int block;                // channels stored together per pixel
  std::size_t plane;        // floats from one block of channels to the next
  bool partial_last_group;  // NHWC with channels not a multiple of 8: the last 8 are partial
};

// The output tile: F(4×4, 3×3) or F(6×6, 3×3) (fewer products, more rounding error).
enum class WinogradTile { f4x4, f6x6 };

class WinogradConv {
 public:
  // True when these weights and parameters, on an input of this size, are a convolution this
  // class computes: a stride-1, pad-1 3×3 one, or a stride-s one with a 3s kernel and pad s
  // (the backbone's 6×6 stride-2 ones) on a multiple of 8 channels, by the space-to-depth view
  // of its input, which makes it a 3×3 one on s²·C channels at 1/s the size.
  static bool handles(const ConvWeights& weights, const ConvParams& params, int height, int width);

  // height and width are the input's. Its workspace (the transformed tiles of a block per
  // thread) is a buffer of the arena's current region, alive until released.
  WinogradConv(const ConvWeights& weights, const ConvParams& params, int height, int width, ChannelLayout input_layout,
               ChannelLayout output_layout, WinogradTile tile, ScratchArena& arena);

  WinogradTile tile() const { return tile_; }

  // The products (tile rows × points) the busiest of omp_get_max_threads() threads computes
  // for a layer of this shape with this tile form: its share of the arithmetic, counting the
  // tiles that overhang the image and the blocks' rounding. faster_tile() picks the form with
  // the smaller share; neuflow-bench-conv times both at every layer to check the choice.
  static long busiest_thread_products(WinogradTile tile, int in_channels, int out_channels, int height, int width);
  static WinogradTile faster_tile(int in_channels, int out_channels, int height, int width);

  // What run() uses only while it runs: release it once the convolution's output is made.
  const dnnl::memory& workspace() const { return workspace_; }

  // input in input_layout; addend (iff params.accumulate) and output in output_layout, a
  // blocked output's padding channels written as zeros.
  void run(const float* input, const float* addend, float* output) const;

 private:
  template <typename T>
  void run_as(const float* input, const float* addend, float* output) const;
  template <typename T>
  void transform_inputs(const float* input, int first_tile, int count, float* points) const;
  template <typename T>
  void transform_outputs(const float* products, int first_tile, int count, const float* addend, float* output) const;
  template <typename T, Activation A>
  void transform_outputs_as(const float* products, int first_tile, int count, const float* addend, float* output) const;

  WinogradTile tile_;
  int output_tile_, points_;  // the tile form's output side and points per tile
  int stride_;
  int height_, width_;  // the output's (the space-to-depth view's)
  ChannelPlacement input_, output_;
  int in_channels_;   // padded to 8
  int out_channels_;  // padded to the output's block (8 in NHWC): what is written
  const winograd::GemmKernel* kernel_;
  int gemm_columns_;  // padded to the kernel's panel: the products' width
  Activation activation_;
  bool accumulate_;
  int tiles_x_, tiles_;
  int block_tiles_;  // a multiple of the kernel's rows
  int blocks_;
  int threads_;
  std::size_t input_stride_, product_stride_;  // floats from one point to the next in a block
  std::size_t thread_floats_;                  // workspace floats each thread uses
  dnnl::memory workspace_;
  // [points][columns / panel][in_channels][panel], shared by every plan of the same model.
  std::shared_ptr<const std::vector<float>> filters_;
  std::vector<float> bias_;  // gemm_columns_ values
};

}  // namespace neuflow::model
