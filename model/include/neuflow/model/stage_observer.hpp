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

}  // namespace neuflow::model
