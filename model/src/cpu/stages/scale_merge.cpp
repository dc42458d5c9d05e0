#include "stages/scale_merge.hpp"

#include "dnnl/context.hpp"

namespace neuflow::model {

ScaleMerge::ScaleMerge(const NetworkWeights& w, int h8, int w8, PlanContext& context) {
  // Built in the order run: both frames' features, then the context. merge0 and merge2 run
  // once per frame, so both frames' outputs are made before merge0's scratch is released
  // (merge0's second run must not write over the first frame's result); what merge2 makes
  // after that may share merge0's scratch, as the two never run at once and merge2's output
  // is read (into the frame's features) before merge0 runs again.
  ScratchArena& arena = context.arena;
  arena.make_tensor(feature_input_, h8, w8, 256);
  merge0_.emplace(w.merge_s8_0, ConvParams{1, 1, Activation::gelu}, nhwc_desc(h8, w8, 256), context);
  for (Tensor& f : features_) arena.make_tensor(f, h8, w8, w.merge_s8_2.out_channels);
  merge0_->release_scratch(arena);
  merge2_.emplace(w.merge_s8_2, ConvParams{1, 1, Activation::none}, merge0_->output_desc(), context);
  merge2_->release_scratch(arena);
  arena.release(feature_input_);
  arena.release(merge0_->output());
  arena.release(merge2_->output());

  arena.make_tensor(context_input_, h8, w8, 128);
  context0_.emplace(w.context_merge_s8_0, ConvParams{1, 1, Activation::gelu}, nhwc_desc(h8, w8, 128), context);
  context2_.emplace(w.context_merge_s8_2, ConvParams{1, 1, Activation::none}, context0_->output_desc(), context);
  arena.make_tensor(context_, h8, w8, context2_->out_channels());
  context0_->release_scratch(arena);
  context2_->release_scratch(arena);
  arena.release(context_input_);
  arena.release(context0_->output());
  arena.release(context2_->output());
}

void ScaleMerge::merge_features(dnnl::stream& stream, const ChannelSlice& feature8, const ChannelSlice& feature16,
                                int frame) {
  copy_channels(feature8, feature_input_, 0);
  upsample_nearest_2x(feature16, feature_input_, feature8.channels);
  merge2_->run_to_nhwc(stream, merge0_->run(stream, wrap_nhwc(feature_input_)),
                       features_[static_cast<std::size_t>(frame)]);
  stream.wait();
}

void ScaleMerge::merge_context(dnnl::stream& stream, const ChannelSlice& context8, const ChannelSlice& context16) {
  copy_channels(context8, context_input_, 0, /*relu=*/true);
  upsample_nearest_2x(context16, context_input_, context8.channels, 1.f, /*relu=*/true);
  context2_->run_to_nhwc(stream, context0_->run(stream, wrap_nhwc(context_input_)), context_);
  stream.wait();
}

}  // namespace neuflow::model
