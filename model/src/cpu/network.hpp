#pragma once
// The whole forward pass at one model resolution: every primitive and buffer is created once
// here and reused for every pair of that size.
#include <dnnl.hpp>

#include "dnnl/plan_context.hpp"
#include "neuflow/model/stage_observer.hpp"
#include "stages/convex_upsampler.hpp"
#include "stages/cross_attention.hpp"
#include "stages/frame_encoder.hpp"
#include "stages/global_matching.hpp"
#include "stages/refinement.hpp"
#include "stages/scale_merge.hpp"
#include "tensor.hpp"
#include "weights.hpp"

namespace neuflow::model {

class NetworkPlan {
 public:
  // height, width: multiples of 16, at least 32. `convolution`: how the stride-1 3×3
  // convolutions are computed (any CpuConvolution; never read from the environment here).
  NetworkPlan(const NetworkWeights& weights, int height, int width, CpuConvolution convolution);

  int height() const { return height_; }
  // The transient activations' arena: its regions (one per stage, overlapping) and the
  // Winograd workspace, for the memory table of neuflow-bench-conv --arena.
  const ScratchArena& arena() const { return context_.arena; }
  int width() const { return width_; }

  // image: [height, width, 3] RGB in 0..1.
  void encode(dnnl::stream& stream, const Tensor& image, FrameFeatures& out);
  // Where a frame may be converted before encode(): a tensor of the arena, see FrameEncoder::input().
  Tensor& input() { return encoder_.input(); }

  // Flow from frame 0 to frame 1 at model resolution: [height, width, 2] (u, v) in pixels, in
  // the arena: valid until the plan's next call.
  const Tensor& flow(dnnl::stream& stream, const FrameFeatures& frame0, const FrameFeatures& frame1, int iters_s16,
                     int iters_s8, const StageObserver* observer = nullptr);

 private:
  int height_, width_;
  PlanContext context_;  // declared before the stages, which take buffers from its arena
  FrameEncoder encoder_;
  CrossAttention attention_;
  GlobalMatching matching_;
  Refinement refine_s16_;
  ScaleMerge merge_;
  Refinement refine_s8_;
  ConvexUpsampler upsampler_;
  Tensor attended0_, attended1_, context16_, flow16_, flow8_;
};

}  // namespace neuflow::model
