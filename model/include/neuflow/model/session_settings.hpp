#pragma once
// What a flow session can be asked to do, with its defaults and limits, in one place. The
// session checks its options here; the GStreamer element's property ranges, the daemon's
// config checks and the CLI's options take their limits and messages from here too, so a
// setting changes in one file. Nothing here needs the network, so the daemon links it alone.
#include <optional>
#include <string>
#include <string_view>

namespace neuflow::model {

enum class ChannelOrder { rgb, bgr };

// Where the network runs: `automatic` ("auto") takes the first discrete or integrated GPU
// through Vulkan and the CPU when there is none; `vulkan` insists on a Vulkan device (a
// software one such as lavapipe included) and fails when there is none.
enum class Backend { automatic, cpu, vulkan };

// What a Vulkan session stores its tensors in: fp32 (exact to the reference), or fp16 (half
// the memory and memory traffic, arithmetic still accumulated in fp32) on devices with
// shaderFloat16 and 16-bit storage; elsewhere fp16 runs as fp32 with a warning. The CPU
// computes in fp32 either way.
enum class Precision { fp32, fp16 };

// How the CPU backend computes its stride-1 3×3 convolutions, most of the network's
// arithmetic: `automatic` by Winograd on the layers where that measured faster than oneDNN's
// direct convolution, F(4×4, 3×3), or F(6×6, 3×3) on the 1/8 refinement's layers where it
// computes fewer products at that size, unless the environment's NEUFLOW_CONV (auto, direct,
// winograd, winograd4 or winograd6) says otherwise; `direct` by oneDNN everywhere (the
// reference path for tests and benchmarks); `winograd` by Winograd on every such layer, tile
// forms chosen as `automatic` does; `winograd4` and `winograd6` by one tile form everywhere,
// to compare them. Winograd's results differ from direct ones by rounding only
// (tests/model/winograd_conv_test.cpp states the bounds).
enum class CpuConvolution { automatic, direct, winograd, winograd4, winograd6 };

// How a stream of frames keeps up (the element's `behaviour` property, neuflowd's `behaviour`
// key): `live` holds real time (the newest frame wins, late ones are dropped), `every_pair`
// computes every consecutive pair (upstream waits, nothing is dropped), `automatic` is live for
// live sources and every-pair otherwise.
enum class Behaviour { automatic, live, every_pair };

struct Iterations {
  int s16 = 1;  // refinement iterations at 1/16
  int s8 = 8;   // refinement iterations at 1/8
  bool operator==(const Iterations&) const = default;
};

struct SessionLimits {
  static constexpr int max_iterations_s16 = 32;
  static constexpr int max_iterations_s8 = 64;
  // The network works on multiples of 16 (its 1/16 feature map); below 32 nothing is left.
  static constexpr int model_side_multiple = 16;
  static constexpr int min_side = 32;
  static constexpr int max_side = 16384;  // frames and model sizes alike
  static constexpr int max_threads = 1024;
  static constexpr int max_device = 63;          // a Vulkan device index; -1: the first GPU
  static constexpr int max_memory_mb = 1 << 20;  // 1 TiB
};

struct SessionOptions {
  Iterations iterations;
  // 0 × 0: run at the input's own size, edge-padded to multiples of 16 and cropped back.
  // Otherwise resize the input to this size (multiples of 16, at least 32) and the flow back,
  // rescaling its vectors to input pixels.
  int model_width = 0;
  int model_height = 0;
  int threads = 0;  // 0: OpenMP's default (all cores)
  // The order the network is fed, whatever order the images hold: RGB as the published
  // weights were trained, BGR as the reference demo scripts (which read with OpenCV) feed it.
  ChannelOrder network_order = ChannelOrder::rgb;
  Backend backend = Backend::automatic;
  // A Vulkan device's index (`neuflow devices` lists them), or -1: the first discrete or
  // integrated GPU (for `vulkan` without one, the first device).
  int device = -1;
  Precision precision = Precision::fp32;
  CpuConvolution cpu_convolution = CpuConvolution::automatic;
  // The most a plan for one model size may take, in MiB (its tensors, the frames it keeps, the
  // flow it returns); 0: three quarters of the memory available when the plan is made.
  int max_memory_mb = 0;
  bool operator==(const SessionOptions&) const = default;
};

// Each check returns what is wrong, worded to follow a setting's name ("expected …, got …"),
// or nothing when the value is usable.
std::optional<std::string> check_iterations_s16(int value);
std::optional<std::string> check_iterations_s8(int value);
std::optional<std::string> check_model_side(int value);  // one of model width/height; 0 allowed
std::optional<std::string> check_threads(int value);
std::optional<std::string> check_device(int value);
std::optional<std::string> check_max_memory(int value);
// Both sides: each usable, and both 0 or both set.
std::optional<std::string> check_model_size(int width, int height);
// The whole set, each problem prefixed with the setting's name ("iters-s8: expected …").
std::optional<std::string> check_session_options(const SessionOptions& options);

struct ModelSize {
  int width = 0;
  int height = 0;
  bool operator==(const ModelSize&) const = default;
};

// The size the network runs at for frames of this size: the options' model size when set,
// else the frame's own size rounded up to multiples of 16.
ModelSize model_size_for(int frame_width, int frame_height, const SessionOptions& options);

constexpr std::string_view channel_order_name(ChannelOrder order) { return order == ChannelOrder::bgr ? "bgr" : "rgb"; }
std::optional<ChannelOrder> parse_channel_order(std::string_view name);

constexpr std::string_view backend_name(Backend backend) {
  return backend == Backend::cpu ? "cpu" : backend == Backend::vulkan ? "vulkan" : "auto";
}
std::optional<Backend> parse_backend(std::string_view name);  // "auto", "cpu", "vulkan"

constexpr std::string_view precision_name(Precision precision) {
  return precision == Precision::fp16 ? "fp16" : "fp32";
}
std::optional<Precision> parse_precision(std::string_view name);  // "fp32", "fp16"

constexpr std::string_view behaviour_name(Behaviour behaviour) {
  return behaviour == Behaviour::live ? "live" : behaviour == Behaviour::every_pair ? "every-pair" : "auto";
}
std::optional<Behaviour> parse_behaviour(std::string_view name);  // "auto", "live", "every-pair"

constexpr std::string_view cpu_convolution_name(CpuConvolution c) {
  switch (c) {
    case CpuConvolution::direct: return "direct";
    case CpuConvolution::winograd: return "winograd";
    case CpuConvolution::winograd4: return "winograd4";
    case CpuConvolution::winograd6: return "winograd6";
    case CpuConvolution::automatic: break;
  }
  return "auto";
}
// "auto", "direct", "winograd", "winograd4", "winograd6"
std::optional<CpuConvolution> parse_cpu_convolution(std::string_view name);

// What the environment's NEUFLOW_CONV asks for, when it is set and not empty; throws
// std::invalid_argument naming the variable when its value is none of those.
std::optional<CpuConvolution> cpu_convolution_from_environment();

}  // namespace neuflow::model
