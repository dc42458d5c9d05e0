#pragma once
// The 1/16 → 1/8 hand-over: features and context at 1/8 merged with their 1/16 counterparts.
#include <dnnl.hpp>

#include <array>
#include <optional>

#include "dnnl/conv_op.hpp"
#include "ops/feature_ops.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class ScaleMerge {
 public:
  // Its outputs stay alive in the current region of the context's arena after it, for the 1/8
  // refinement built next in the same region; what it uses only while it runs is released.
  ScaleMerge(const NetworkWeights& weights, int h8, int w8, PlanContext& context);

  // merge_s8(concat[feature8, up2x(feature16)]) → features(frame) [h8, w8, 128].
  void merge_features(dnnl::stream& stream, const ChannelSlice& feature8, const ChannelSlice& feature16, int frame);

  // context_merge_s8(concat[relu(context8), up2x(relu(context16))]) → context() [h8, w8, 64].
  void merge_context(dnnl::stream& stream, const ChannelSlice& context8, const ChannelSlice& context16);

  const Tensor& features(int frame) const { return features_[static_cast<std::size_t>(frame)]; }
  const Tensor& context() const { return context_; }

 private:
  Tensor feature_input_, context_input_;  // in the arena: rewritten whole by each call
  std::array<Tensor, 2> features_;
  Tensor context_;
  std::optional<ConvOp> merge0_, merge2_, context0_, context2_;
};

}  // namespace neuflow::model
