#include "stages/scale_merge.hpp"

#include "dnnl/context.hpp"

namespace neuflow::model {

ScaleMerge::ScaleMerge(const NetworkWeights& w, int h8, int w8, PlanContext& context) {
  context.arena.make_tensor(feature_input_, h8, w8, 256);
  context.arena.make_tensor(context_input_, h8, w8, 128);
  merge0_.emplace(w.merge_s8_0, ConvParams{1, 1, Activation::gelu}, nhwc_desc(h8, w8, 256), context);
  merge2_.emplace(w.merge_s8_2, ConvParams{1, 1, Activation::none}, merge0_->output_desc(), context);
  context0_.emplace(w.context_merge_s8_0, ConvParams{1, 1, Activation::gelu}, nhwc_desc(h8, w8, 128), context);
  context2_.emplace(w.context_merge_s8_2, ConvParams{1, 1, Activation::none}, context0_->output_desc(), context);
}

void ScaleMerge::merge_features(dnnl::stream& stream, const ChannelSlice& feature8, const ChannelSlice& feature16,
                                Tensor& out) {
  copy_channels(feature8, feature_input_, 0);
  upsample_nearest_2x(feature16, feature_input_, feature8.channels);
  merge2_->run_to_nhwc(stream, merge0_->run(stream, wrap_nhwc(feature_input_)), out);
  stream.wait();
}

void ScaleMerge::merge_context(dnnl::stream& stream, const ChannelSlice& context8, const ChannelSlice& context16,
                               Tensor& out) {
  copy_channels(context8, context_input_, 0, /*relu=*/true);
  upsample_nearest_2x(context16, context_input_, context8.channels, 1.f, /*relu=*/true);
  context2_->run_to_nhwc(stream, context0_->run(stream, wrap_nhwc(context_input_)), out);
  stream.wait();
}

}  // namespace neuflow::model
