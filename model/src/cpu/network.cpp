#include "network.hpp"

#include <string>
#include <string_view>

#include "ops/feature_ops.hpp"

namespace neuflow::model {

namespace {

void observe(const StageObserver* observer, std::string_view name, int frame, const Tensor& t) {
  if (!observer || !*observer) return;
  const std::string stage_name(name);
  (*observer)(StageTensor{stage_name, frame, t.h, t.w, t.c, t.data.data()});
}

ChannelSlice features_of(const Tensor& t) { return {&t, kContextChannels, kMatchingChannels}; }
ChannelSlice context_of(const Tensor& t) { return {&t, 0, kContextChannels}; }

// Starts a new arena region: the stage constructed with it may reuse earlier stages' memory.
PlanContext& next_region(PlanContext& context, const char* name) {
  context.arena.next_region(name);
  return context;
}

PlanContext& first_region(PlanContext& context, const char* name) {
  context.arena.name_region(name);
  return context;
}

}  // namespace

NetworkPlan::NetworkPlan(const NetworkWeights& w, int height, int width, CpuConvolution convolution)
    : height_(height),
      width_(width),
      context_{{}, convolution},
      encoder_(w, height, width, first_region(context_, "encoder")),
      attention_(w, height / 16, width / 16, next_region(context_, "cross_attention")),
      matching_(height / 16, width / 16, kMatchingChannels, next_region(context_, "global_matching")),
      refine_s16_(w.refine_s16, height / 16, width / 16, Iterations{}.s16, next_region(context_, "refine_s16")),
      merge_(w, height / 8, width / 8, next_region(context_, "merge_refine_s8")),
      refine_s8_(w.refine_s8, height / 8, width / 8, Iterations{}.s8,
                 context_),  // same region: it reads the merges' outputs
      upsampler_(w, height / 8, width / 8, next_region(context_, "upsampler")),
      context16_(height / 16, width / 16, kContextChannels),
      flow8_(height / 8, width / 8, 2) {
  context_.arena.finalize();
}

void NetworkPlan::encode(dnnl::stream& stream, const Tensor& image, FrameFeatures& out) {
  encoder_.run(stream, image, out);
  stream.wait();
}

const Tensor& NetworkPlan::flow(dnnl::stream& stream, const FrameFeatures& f0, const FrameFeatures& f1, int iters_s16,
                                int iters_s8, const StageObserver* observer) {
  observe(observer, stage::backbone_s16, 0, f0.f16);
  observe(observer, stage::backbone_s16, 1, f1.f16);
  observe(observer, stage::backbone_s8, 0, f0.f8);
  observe(observer, stage::backbone_s8, 1, f1.f8);
  observe(observer, stage::conv_s8, 0, f0.upsample_features);

  // 1/16: cross-attention, global matching, refinement.
  attention_.run(stream, f0.f16, f1.f16, attended0_, attended1_);
  observe(observer, stage::cross_attn_s16, 0, attended0_);
  observe(observer, stage::cross_attn_s16, 1, attended1_);

  matching_.run(stream, features_of(attended0_), features_of(attended1_), flow16_);
  observe(observer, stage::global_matching_flow, 0, flow16_);

  copy_channels(context_of(attended0_), context16_, 0, /*relu=*/true);
  refine_s16_.begin(stream, context16_);
  for (int i = 0; i < iters_s16; ++i) {
    refine_s16_.step(stream, features_of(attended0_), features_of(attended1_), flow16_);
    if (observer) {
      observe(observer, stage::corr_iteration(stage::scale_s16, i), 0,
              extract_channels({&refine_s16_.last_input(), 0, kCorrChannels}));
      observe(observer, stage::refine_iteration(stage::scale_s16, i) + "_hidden", 0, refine_s16_.hidden());
      observe(observer, stage::refine_iteration(stage::scale_s16, i) + "_delta", 0, refine_s16_.delta());
    }
  }

  // 1/16 → 1/8.
  upsample_nearest_2x(all_channels(flow16_), flow8_, 0, 2.f);
  merge_.merge_features(stream, features_of(f0.f8), features_of(attended0_), 0);
  merge_.merge_features(stream, features_of(f1.f8), features_of(attended1_), 1);
  observe(observer, stage::merge_s8, 0, merge_.features(0));
  observe(observer, stage::merge_s8, 1, merge_.features(1));
  merge_.merge_context(stream, context_of(f0.f8), context_of(attended0_));
  observe(observer, stage::context_merge_s8, 0, merge_.context());

  // 1/8 refinement.
  refine_s8_.begin(stream, merge_.context());
  for (int i = 0; i < iters_s8; ++i) {
    refine_s8_.step(stream, all_channels(merge_.features(0)), all_channels(merge_.features(1)), flow8_);
    if (observer) {
      observe(observer, stage::corr_iteration(stage::scale_s8, i), 0,
              extract_channels({&refine_s8_.last_input(), 0, kCorrChannels}));
      observe(observer, stage::refine_iteration(stage::scale_s8, i) + "_hidden", 0, refine_s8_.hidden());
      observe(observer, stage::refine_iteration(stage::scale_s8, i) + "_delta", 0, refine_s8_.delta());
    }
  }

  const Tensor& out = upsampler_.run(stream, flow8_, f0.upsample_features);
  observe(observer, stage::flow, 0, out);
  return out;
}

}  // namespace neuflow::model
