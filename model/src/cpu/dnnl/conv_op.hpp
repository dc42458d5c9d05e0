#pragma once
// One convolution, created once per input size: a oneDNN primitive (weights reordered to the
// layout it wants, bias and activation fused), or for a stride-1 3×3 one where the plan says
// so, Winograd F(4×4, 3×3) on oneDNN's 8-channel blocked layout. Output buffer owned here.
#include <dnnl.hpp>

#include <optional>

#include "dnnl/conv_params.hpp"
#include "dnnl/plan_context.hpp"
#include "tensor.hpp"
#include "weights.hpp"
#include "winograd/winograd_conv.hpp"

namespace neuflow::model {

class ConvOp {
 public:
  // `input` describes the memory run() will receive: NHWC from a stage, or a previous
  // ConvOp's output(). The output and any reordered input live in the context's arena
  // (current region). `output` forces the output layout (default: the primitive's choice).
  // Without `own_output`, the output has no memory until set_output() gives it some.
  ConvOp(const ConvWeights& weights, const ConvParams& params, const dnnl::memory::desc& input, PlanContext& context,
         std::optional<dnnl::memory::desc> output = std::nullopt, bool own_output = true);

  // Runs the convolution; `addend` (required iff params.accumulate) must have output_desc().
  const dnnl::memory& run(dnnl::stream& stream, const dnnl::memory& input, const dnnl::memory* addend = nullptr);

  // Runs and converts the output to NHWC into `out` (resized as needed).
  void run_to_nhwc(dnnl::stream& stream, const dnnl::memory& input, Tensor& out, const dnnl::memory* addend = nullptr);

  const dnnl::memory& output() const { return dst_; }
  // From now on the output goes to `data` (laid out as output_desc()).
  void set_output(void* data) { dst_.set_data_handle(data); }
  dnnl::memory::desc output_desc() const { return dst_.get_desc(); }
  int out_h() const { return out_h_; }
  int out_w() const { return out_w_; }
  int out_channels() const { return out_c_; }
  bool is_winograd() const { return winograd_.has_value(); }

  // Releases to `arena` what this convolution needs only while it runs (an input converted
  // to its layout, the Winograd workspace); see ScratchArena::release.
  void release_scratch(ScratchArena& arena) const {
    if (input_reorder_) arena.release(reordered_input_);
    if (winograd_) arena.release(winograd_->workspace());
  }

 private:
  int out_h_ = 0, out_w_ = 0, out_c_ = 0;
  bool accumulate_ = false;
  std::optional<WinogradConv> winograd_;
  std::optional<dnnl::eltwise_forward> gelu_;  // after a Winograd convolution with GELU
  dnnl::convolution_forward conv_;
  dnnl::memory weights_, bias_, dst_;
  std::optional<dnnl::reorder> input_reorder_;
  dnnl::memory reordered_input_;
  std::optional<dnnl::reorder> nhwc_reorder_;
};

// Copies any oneDNN memory into an NHWC tensor (reorder; the primitive cache makes repeats cheap).
void to_nhwc(dnnl::stream& stream, const dnnl::memory& src, Tensor& out);

}  // namespace neuflow::model
