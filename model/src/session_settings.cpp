#include "neuflow/model/session_settings.hpp"

#include <cstdlib>
#include <stdexcept>
#include <string>

namespace neuflow::model {

namespace {

std::optional<std::string> check_range(int value, int max, std::string_view what) {
  if (value >= 0 && value <= max) return std::nullopt;
  return "expected " + std::string(what) + " 0 to " + std::to_string(max) + ", got " + std::to_string(value);
}

int round_up(int value, int multiple) { return (value + multiple - 1) / multiple * multiple; }

}  // namespace

std::optional<std::string> check_iterations_s16(int value) {
  return check_range(value, SessionLimits::max_iterations_s16, "a number of iterations");
}

std::optional<std::string> check_iterations_s8(int value) {
  return check_range(value, SessionLimits::max_iterations_s8, "a number of iterations");
}

std::optional<std::string> check_threads(int value) {
  return check_range(value, SessionLimits::max_threads, "a thread count (0: all cores)");
}

std::optional<std::string> check_device(int value) {
  if (value >= -1 && value <= SessionLimits::max_device) return std::nullopt;
  return "expected a Vulkan device index 0 to " + std::to_string(SessionLimits::max_device) +
         " (or -1 for the first GPU), got " + std::to_string(value);
}

std::optional<std::string> check_model_side(int value) {
  using L = SessionLimits;
  if (value == 0 || (value >= L::min_side && value <= L::max_side && value % L::model_side_multiple == 0)) {
    return std::nullopt;
  }
  return "expected a multiple of " + std::to_string(L::model_side_multiple) + ", at least " +
         std::to_string(L::min_side) + " (or 0 for the frames' own size), got " + std::to_string(value);
}

std::optional<std::string> check_model_size(int width, int height) {
  if (auto problem = check_model_side(width)) return "model-width: " + *problem;
  if (auto problem = check_model_side(height)) return "model-height: " + *problem;
  if ((width == 0) != (height == 0)) {
    return "model-width and model-height go together: both 0 (the frames' own size) or both set, got " +
           std::to_string(width) + "x" + std::to_string(height);
  }
  return std::nullopt;
}

std::optional<std::string> check_max_memory(int value) {
  if (value >= 0 && value <= SessionLimits::max_memory_mb) return std::nullopt;
  return "expected MiB from 0 (three quarters of the available memory) to " +
         std::to_string(SessionLimits::max_memory_mb) + ", got " + std::to_string(value);
}

std::optional<std::string> check_session_options(const SessionOptions& options) {
  if (auto problem = check_iterations_s16(options.iterations.s16)) return "iters-s16: " + *problem;
  if (auto problem = check_iterations_s8(options.iterations.s8)) return "iters-s8: " + *problem;
  if (auto problem = check_model_size(options.model_width, options.model_height)) return problem;
  if (auto problem = check_threads(options.threads)) return "threads: " + *problem;
  if (auto problem = check_device(options.device)) return "device: " + *problem;
  if (auto problem = check_max_memory(options.max_memory_mb)) return "max-memory: " + *problem;
  return std::nullopt;
}

ModelSize model_size_for(int frame_width, int frame_height, const SessionOptions& options) {
  if (options.model_width > 0 && options.model_height > 0) return {options.model_width, options.model_height};
  return {round_up(frame_width, SessionLimits::model_side_multiple),
          round_up(frame_height, SessionLimits::model_side_multiple)};
}

std::optional<ChannelOrder> parse_channel_order(std::string_view name) {
  if (name == "rgb") return ChannelOrder::rgb;
  if (name == "bgr") return ChannelOrder::bgr;
  return std::nullopt;
}

std::optional<Precision> parse_precision(std::string_view name) {
  if (name == "fp32") return Precision::fp32;
  if (name == "fp16") return Precision::fp16;
  return std::nullopt;
}

std::optional<Backend> parse_backend(std::string_view name) {
  if (name == "auto") return Backend::automatic;
  if (name == "cpu") return Backend::cpu;
  if (name == "vulkan") return Backend::vulkan;
  return std::nullopt;
}

std::optional<Behaviour> parse_behaviour(std::string_view name) {
  for (const Behaviour b : {Behaviour::automatic, Behaviour::live, Behaviour::every_pair}) {
    if (name == behaviour_name(b)) return b;
  }
  return std::nullopt;
}

std::optional<CpuConvolution> parse_cpu_convolution(std::string_view name) {
  if (name == "auto") return CpuConvolution::automatic;
  if (name == "direct") return CpuConvolution::direct;
  if (name == "winograd") return CpuConvolution::winograd;
  if (name == "winograd4") return CpuConvolution::winograd4;
  if (name == "winograd6") return CpuConvolution::winograd6;
  return std::nullopt;
}

std::optional<CpuConvolution> cpu_convolution_from_environment() {
  const char* value = std::getenv("NEUFLOW_CONV");
  if (!value || !*value) return std::nullopt;
  if (const auto parsed = parse_cpu_convolution(value)) return parsed;
  throw std::invalid_argument(
      std::string("NEUFLOW_CONV: expected auto, direct, winograd, winograd4 or winograd6, got \"") + value + "\"");
}

}  // namespace neuflow::model
