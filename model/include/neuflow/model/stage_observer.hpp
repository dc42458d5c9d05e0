#pragma once
// A hook that sees every named intermediate of a forward pass, for comparing a run against
// reference tensors stage by stage (the names follow docs/neuflow-v2-network.md and the
// fixture files: "backbone_s16", "refine_s8_iter3_hidden", "flow", ...).
#include <functional>
#include <string>

namespace neuflow::model {

struct StageTensor {
  const std::string& name;
  int frame;  // 0 or 1 for per-frame tensors, else 0
  int height;
  int width;
  int channels;
  const float* data;  // NHWC: channels fastest
};

using StageObserver = std::function<void(const StageTensor&)>;

// How long a stage ran on the device, from the GPU's own timestamps (FlowSession::
// device_stage_times()). Named as the observer's stages, except that a refinement iteration is
// one stage ("refine_s8_iter0"); each runs from the end of the stage before it ("backbone_s8"
// of a frame's encoding from the frame's upload, "merge_s8" includes resampling the flow to 1/8).
struct StageTime {
  std::string name;
  double milliseconds;
};

}  // namespace neuflow::model
