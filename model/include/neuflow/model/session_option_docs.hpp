#pragma once
// The session's settings as users meet them: the `neuflow` element's properties, the command's
// --options and neuflowd's [stream.flow] keys carry these names and help texts, so a setting is
// named and explained once (the values' limits are SessionLimits', session_settings.hpp).
#include <string_view>

namespace neuflow::model {

struct OptionDoc {
  std::string_view name;  // the property, the option without its dashes, the config key
  std::string_view help;  // one line, no trailing full stop
};

namespace option_docs {

inline constexpr OptionDoc iters_s16{"iters-s16", "Refinement iterations at 1/16 resolution"};
inline constexpr OptionDoc iters_s8{"iters-s8", "Refinement iterations at 1/8 resolution"};
inline constexpr OptionDoc model_width{
    "model-width", "Width the network runs at (multiple of 16); 0: the frames' own size, edge-padded"};
inline constexpr OptionDoc model_height{
    "model-height", "Height the network runs at (multiple of 16); 0: the frames' own size, edge-padded"};
inline constexpr OptionDoc threads{"threads", "CPU threads for inference (0: all cores)"};
inline constexpr OptionDoc channel_order{
    "channel-order",
    "Colour order fed to the network: rgb (what the published weights were trained with) or bgr (as the reference "
    "demo scripts feed it)"};
inline constexpr OptionDoc backend{
    "backend",
    "Where the network runs: auto (the first discrete or integrated GPU through Vulkan, else the CPU, with a warning "
    "when a GPU fails), cpu, or vulkan (any Vulkan device, software ones included; fails without one)"};
inline constexpr OptionDoc device{
    "device", "Vulkan device index as `neuflow devices` lists them; -1: the first discrete or integrated GPU"};
inline constexpr OptionDoc precision{
    "precision",
    "What a Vulkan device stores tensors in: fp32 (exact), or fp16 (half the memory; devices with shaderFloat16, "
    "else fp32 with a warning); the CPU computes in fp32 either way"};
inline constexpr OptionDoc max_memory{
    "max-memory",
    "MiB a model size's plan may take (its tensors, the frames it keeps, the flow it returns); a larger one is refused "
    "with the need named. 0: three quarters of the memory available then"};
inline constexpr OptionDoc behaviour{
    "behaviour",
    "How a stream keeps up: live holds real time by dropping frames, every-pair computes every consecutive pair, "
    "auto is live for live sources and every-pair otherwise"};

}  // namespace option_docs
}  // namespace neuflow::model
