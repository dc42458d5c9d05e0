#pragma once
// The 1/16 → 1/8 hand-over: features and context at 1/8 merged with their 1/16 counterparts.
#include <dnnl.hpp>

#include <optional>

#include "dnnl/conv_op.hpp"
#include "ops/feature_ops.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class ScaleMerge {
 public:
  ScaleMerge(const NetworkWeights& weights, int h8, int w8, PlanContext& context);

  // merge_s8(concat[feature8, up2x(feature16)]) → out [h8, w8, 128].
  void merge_features(dnnl::stream& stream, const ChannelSlice& feature8, const ChannelSlice& feature16, Tensor& out);

  // context_merge_s8(concat[relu(context8), up2x(relu(context16))]) → out [h8, w8, 64].
  void merge_context(dnnl::stream& stream, const ChannelSlice& context8, const ChannelSlice& context16, Tensor& out);

 private:
  Tensor feature_input_, context_input_;  // in the arena: rewritten whole by each call
  std::optional<ConvOp> merge0_, merge2_, context0_, context2_;
};

}  // namespace neuflow::model
