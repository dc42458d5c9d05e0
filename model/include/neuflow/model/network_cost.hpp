#pragma once
// The arithmetic NeuFlow-V2 costs at a given model size, stage by stage: multiply-adds × 2
// of the convolutions and matrix products this implementation performs. The reference
// additionally builds the all-pairs 1/8 correlation volume ((HW/64)² · 256 FLOP), which the
// network doc's cost table includes and this core never computes, and recomputes at every
// refinement step the share of conv1 that reads the context (65 of its 212 inputs), which this
// core computes once a pair. What the GPU's commands count (DeviceWork) adds up to this.
#include "neuflow/model/session_settings.hpp"

namespace neuflow::model {

struct NetworkCost {
  double backbone = 0;           // one frame
  double upsample_features = 0;  // conv_s8, one frame
  double cross_attention = 0;
  double global_matching = 0;
  double refine_s16 = 0;
  double merge_s8 = 0;
  double refine_s8 = 0;
  double upsampler = 0;

  // A pair computed from scratch: both frames encoded.
  double pair() const { return 2 * backbone + 2 * upsample_features + per_pair(); }
  // One frame of a stream: one frame encoded, the other's features reused.
  double stream_frame() const { return backbone + upsample_features + per_pair(); }

 private:
  double per_pair() const { return cross_attention + global_matching + refine_s16 + merge_s8 + refine_s8 + upsampler; }
};

// height, width: the model resolution (multiples of 16).
NetworkCost network_cost(int height, int width, const Iterations& iterations = {});

}  // namespace neuflow::model
