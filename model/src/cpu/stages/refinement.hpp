#pragma once
// The iterative refinement block at one scale. The first convolution's input is
// [corr, context, hidden, flow, radius]; context and radius do not change within a pair, so
// their share of that convolution is computed once in begin() and added at every step.
#include <dnnl.hpp>

#include <array>
#include <optional>

#include "dnnl/conv_op.hpp"
#include "ops/feature_ops.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class Refinement {
 public:
  // iterations: how many steps a pair usually runs (the session's default at this scale);
  // above one, the per-step convolutions are marked ConvParams::repeated.
  Refinement(const RefineWeights& weights, int h, int w, int iterations, PlanContext& context);

  // Starts a pair: context [h, w, 64]; hidden state reset to zero.
  void begin(dnnl::stream& stream, const Tensor& context);

  // One iteration: correlation around the current flow, then flow += delta.
  void step(dnnl::stream& stream, const ChannelSlice& f0, const ChannelSlice& f1, Tensor& flow);

  // The input of the last step's first convolution: channels 0..80 are the correlation.
  const Tensor& last_input() const { return input_; }
  // The last step's hidden state and flow update (copies, for an observer).
  Tensor hidden() const;
  Tensor delta() const;

 private:
  Tensor input_;     // [corr 81, hidden 64, flow 2]
  Tensor constant_;  // [context 64, radius plane]
  Tensor output_;    // conv3: [delta 2, hidden 64]
  std::optional<ConvOp> conv1_constant_, conv1_, conv2_, conv3_;
  std::array<std::optional<ConvOp>, 5> layers_;
};

}  // namespace neuflow::model
