#pragma once
// One convolution as a oneDNN primitive, created once per input size: weights reordered to
// the layout the primitive wants, bias and activation fused, output buffer owned here.
#include <dnnl.hpp>

#include <optional>

#include "dnnl/scratch_arena.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

enum class Activation { none, leaky_relu, relu, gelu };

struct ConvParams {
  int stride = 1;
  int pad = 0;
  Activation activation = Activation::none;
  // Adds a tensor given at run time to the convolution's result before the activation.
  // Used to add the per-pair constant part of the refinement's first convolution.
  bool accumulate = false;
};

class ConvOp {
 public:
  // `input` describes the memory run() will receive: NHWC from a stage, or a previous
  // ConvOp's output(). The output and any reordered input live in `arena` (current region).
  // `output` forces the output layout (default: the primitive's choice).
  ConvOp(const ConvWeights& weights, const ConvParams& params, const dnnl::memory::desc& input,
         ScratchArena& arena, std::optional<dnnl::memory::desc> output = std::nullopt);

  // Runs the convolution; `addend` (required iff params.accumulate) must have output_desc().
  const dnnl::memory& run(dnnl::stream& stream, const dnnl::memory& input,
                          const dnnl::memory* addend = nullptr);

  // Runs and converts the output to NHWC into `out` (resized as needed).
  void run_to_nhwc(dnnl::stream& stream, const dnnl::memory& input, Tensor& out,
                   const dnnl::memory* addend = nullptr);

  const dnnl::memory& output() const { return dst_; }
  dnnl::memory::desc output_desc() const { return dst_.get_desc(); }
  int out_h() const { return out_h_; }
  int out_w() const { return out_w_; }
  int out_channels() const { return out_c_; }

 private:
  int out_h_ = 0, out_w_ = 0, out_c_ = 0;
  bool accumulate_ = false;
  dnnl::convolution_forward conv_;
  dnnl::memory weights_, bias_, dst_;
  std::optional<dnnl::reorder> input_reorder_;
  dnnl::memory reordered_input_;
  std::optional<dnnl::reorder> nhwc_reorder_;
};

// Copies any oneDNN memory into an NHWC tensor (reorder; the primitive cache makes repeats cheap).
void to_nhwc(dnnl::stream& stream, const dnnl::memory& src, Tensor& out);

}  // namespace neuflow::model
