#pragma once
// A hook that sees every named intermediate of a forward pass, for comparing a run against
// reference tensors stage by stage (the names follow docs/neuflow-v2-network.md and the
// fixture files: "backbone_s16", "refine_s8_iter3_hidden", "flow", ...).
#include <functional>
#include <string>
#include <string_view>

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

// The stages' names, defined once: both backends name their stages with these, and the
// observer, the GPU timestamps and the benchmark read them.
namespace stage {
inline constexpr std::string_view backbone_s16 = "backbone_s16";
inline constexpr std::string_view backbone_s8 = "backbone_s8";
inline constexpr std::string_view conv_s8 = "conv_s8";  // the upsampler's frame features
inline constexpr std::string_view cross_attn_s16 = "cross_attn_s16";
inline constexpr std::string_view global_matching_flow = "global_matching_flow";
inline constexpr std::string_view merge_s8 = "merge_s8";
inline constexpr std::string_view context_merge_s8 = "context_merge_s8";
inline constexpr std::string_view flow = "flow";
inline constexpr std::string_view scale_s16 = "s16";  // the refinements' scales
inline constexpr std::string_view scale_s8 = "s8";

// A refinement iteration ("refine_s8_iter3"), its correlation ("corr_s8_iter3") and its
// outputs ("refine_s8_iter3_hidden", "refine_s8_iter3_delta").
// What every iteration's names at a scale begin with ("refine_s8_iter", "corr_s8_iter").
inline std::string refine_prefix(std::string_view scale) { return "refine_" + std::string(scale) + "_iter"; }
inline std::string corr_prefix(std::string_view scale) { return "corr_" + std::string(scale) + "_iter"; }
inline std::string refine_iteration(std::string_view scale, int i) { return refine_prefix(scale) + std::to_string(i); }
inline std::string corr_iteration(std::string_view scale, int i) { return corr_prefix(scale) + std::to_string(i); }
}  // namespace stage

// How long a stage ran on the device, from the GPU's own timestamps (FlowSession::
// device_stage_times()). Named as the observer's stages, except that a refinement iteration is
// one stage ("refine_s8_iter0"); each runs from the end of the stage before it ("conv_s8", a
// frame's first, from the frame's upload; "merge_s8" includes resampling the flow to 1/8).
struct StageTime {
  std::string name;
  double milliseconds;
};

}  // namespace neuflow::model
