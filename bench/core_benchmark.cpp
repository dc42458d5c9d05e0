// Benchmarks of the NeuFlow-V2 core: per pair and per streamed frame at the sizes of the
// reference measurements, with achieved GFLOP/s as a fraction of the sgemm peak measured in
// the same process (absolute times on a shared machine drift; the ratio does not). The CPU
// runs twice: `direct_*` with every convolution by oneDNN's direct algorithm, then the
// default (Winograd on the stride-1 3×3 layers), whose `x_direct` is its speed-up over the
// direct run just before. GFLOP/s always counts the direct convolutions' arithmetic.
//
// With --backend vulkan the GPU runs the same pairs and streams (`x_cpu`: the CPU's time over
// the GPU's), `vulkan_stream_pipelined` streams with a frame in flight (its `x_push`: the
// plain stream's time over its own), and `vulkan_stream_stages` splits a streamed frame by the
// GPU's timestamps. `--precision fp32,fp16` runs the GPU's benchmarks in both precisions, fp16
// as `vulkan_fp16_*` with `x_fp32`: the fp32 time of the same benchmark in this run over its
// own (a device without fp16 reports that as the benchmark's error instead of a figure).
// The GPU's stream benchmarks also count what a streamed frame asks of the device (dispatches,
// barriers, submissions, host waits, GMAC, MB read and written, from the commands' shapes);
// --work prints every command of that frame.
//
//   neuflow-bench-core [--model CKPT] [--threads N] [--sizes 320x256,768x432]
//                      [--backend cpu|vulkan] [--device N] [--precision fp32|fp16|fp32,fp16] [--work]
//                      [benchmark flags]
//
// Peak RSS is per process: run one size per process for per-size peaks (bench/run-core.sh).
#include <benchmark/benchmark.h>
#include <omp.h>
#include <oneapi/dnnl/dnnl.h>
#include <sys/resource.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

#include "device_work_report.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/network_cost.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/model/stage_observer.hpp"

namespace {

constexpr const char* kUsage =
    "neuflow-bench-core: the CPU's (and with --backend vulkan the GPU's) pair, stream and stage times, against the "
    "sgemm peak\n"
    "  --model CKPT          checkpoint (default: $NEUFLOW_MODEL, else the shared fixture's random weights)\n"
    "  --frames DIR          frames to push (default: the shared fixture's camera sequence)\n"
    "  --threads N           OpenMP threads (default: 2)\n"
    "  --sizes WxH[,WxH...]  model sizes (default: 320x256,512x384,768x432,1024x448)\n"
    "  --backend cpu|vulkan  vulkan also runs the CPU, to compare\n"
    "  --device N            the Vulkan device (`neuflow devices`)\n"
    "  --precision fp32|fp16|fp32,fp16   the GPU's precisions\n"
    "  --work                print every command a streamed frame gives the GPU\n"
    "Google Benchmark's flags:\n";

using neuflow::model::FlowModel;
using neuflow::model::FlowSession;
using neuflow::model::ImageView;

struct Config {
  std::filesystem::path model;
  std::filesystem::path frames;
  int threads = 2;
  bool vulkan = false;  // --backend vulkan: the Vulkan backend too, against the CPU in the same run
  int device = -1;
  std::vector<neuflow::model::Precision> precisions{neuflow::model::Precision::fp32};  // of the GPU's runs
  std::vector<std::pair<int, int>> sizes{{320, 256}, {512, 384}, {768, 432}, {1024, 448}};
  bool work_tables = false;  // --work
};

Config g_config;
double g_sgemm_peak_gflops = 0;
std::map<std::string, double> g_cpu_ms;     // "pair/768x432" → the CPU's time in this run
std::map<std::string, double> g_direct_ms;  // the same with direct convolutions only
std::shared_ptr<const FlowModel> g_model;

double peak_rss_mb() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return static_cast<double>(u.ru_maxrss) / 1024.0;
}

// sgemm at a size large enough to reach the machine's peak; the best of several runs.
void BM_SgemmPeak(benchmark::State& state) {
  omp_set_num_threads(g_config.threads);
  const int n = static_cast<int>(state.range(0));
  std::vector<float> a(static_cast<std::size_t>(n) * n, 1.f), b(a.size(), 0.5f), c(a.size());
  double best = 0;
  for (auto _ : state) {
    const auto t0 = std::chrono::steady_clock::now();
    dnnl_sgemm('N', 'N', n, n, n, 1.f, a.data(), n, b.data(), n, 0.f, c.data(), n);
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    best = std::max(best, 2.0 * n * n * n / s / 1e9);
    benchmark::DoNotOptimize(c.data());
  }
  g_sgemm_peak_gflops = std::max(g_sgemm_peak_gflops, best);
  state.counters["GFLOP/s"] = best;
}

// The sample frames, kept encoded and decoded one at a time as a benchmark asks for them
// (outside its timed window), so the peak RSS it reports is the session's and a frame or two,
// as in a live stream, not every decoded frame at once (69 MB at 1920×1088).
class FrameSequence {
 public:
  FrameSequence(int width, int height) : width_(width), height_(height) {
    std::vector<std::filesystem::path> files;
    if (std::filesystem::is_directory(g_config.frames)) {
      for (const auto& e : std::filesystem::directory_iterator(g_config.frames)) {
        if (e.path().extension() == ".jpg" || e.path().extension() == ".png") files.push_back(e.path());
      }
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::ifstream in(f, std::ios::binary);
      std::vector<uchar> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      if (!cv::imdecode(bytes, cv::IMREAD_COLOR).empty()) encoded_.push_back(std::move(bytes));
    }
    if (encoded_.size() < 2) encoded_.clear();  // no fixture frames: a moving gradient stands in
  }

  // Frame i of the cycle, resized to the benchmark's size.
  cv::Mat at(std::size_t i) const {
    cv::Mat frame;
    if (encoded_.empty()) {
      frame.create(height_, width_, CV_8UC3);
      const int shift = static_cast<int>(3 * (i % kGradientFrames));
      for (int y = 0; y < height_; ++y)
        for (int x = 0; x < width_; ++x)
          frame.at<cv::Vec3b>(y, x) = cv::Vec3b((x + shift) & 255, y & 255, (x ^ y) & 255);
      return frame;
    }
    const cv::Mat decoded = cv::imdecode(encoded_[i % encoded_.size()], cv::IMREAD_COLOR);
    cv::resize(decoded, frame, cv::Size(width_, height_), 0, 0, cv::INTER_AREA);
    return frame;
  }

 private:
  static constexpr std::size_t kGradientFrames = 4;
  int width_, height_;
  std::vector<std::vector<uchar>> encoded_;
};

ImageView view(const cv::Mat& m) {
  return {m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), neuflow::model::ChannelOrder::bgr};
}

void report(benchmark::State& state, double seconds_per_item, double flops) {
  const double gflops = flops / seconds_per_item / 1e9;
  state.counters["ms"] = seconds_per_item * 1e3;
  state.counters["GFLOP/s"] = gflops;
  state.counters["of_sgemm_peak"] = g_sgemm_peak_gflops > 0 ? gflops / g_sgemm_peak_gflops : 0;
  state.counters["peak_rss_MB"] = peak_rss_mb();
}

// What one benchmark runs on: a backend, and on the CPU how its 3×3 convolutions are computed.
struct Variant {
  neuflow::model::Backend backend = neuflow::model::Backend::cpu;
  neuflow::model::CpuConvolution convolution = neuflow::model::CpuConvolution::automatic;
  neuflow::model::Precision precision = neuflow::model::Precision::fp32;
};

neuflow::model::SessionOptions options_for(const Variant& v) {
  return {.threads = g_config.threads,
          .backend = v.backend,
          .device = g_config.device,
          .precision = v.precision,
          .cpu_convolution = v.convolution};
}

bool is_fp16(const Variant& v) { return v.precision == neuflow::model::Precision::fp16; }

// What the GPU's benchmarks are named after: vulkan_pair/…, vulkan_fp16_pair/…
std::string gpu_prefix(neuflow::model::Precision precision) {
  return precision == neuflow::model::Precision::fp16 ? "vulkan_fp16_" : "vulkan_";
}

// A GPU benchmark's label; false (the benchmark reports an error, no figure) when the session
// does not run as asked: fp16 on a device without it runs in fp32.
bool label_gpu_run(benchmark::State& state, const FlowSession& session, const Variant& v) {
  if (is_fp16(v) && session.backend_description().find(", fp16") == std::string::npos) {
    state.SkipWithError(session.fallback_warning().empty() ? "fp16 was asked for and the session runs in fp32"
                                                           : session.fallback_warning().c_str());
    return false;
  }
  state.SetLabel(session.backend_description());
  return true;
}

std::map<std::string, double> g_vulkan_fp32_ms;  // "stream/768x432" → the GPU's fp32 time in this run

// The CPU's default against its direct-only run of the same work, measured just before; on
// the Vulkan backend, the time against the CPU's default, and in fp16 against fp32 on the same
// device. `gpu_key` names the GPU benchmark where it differs from the CPU one it is set against.
void compare(benchmark::State& state, const std::string& key, const Variant& v, std::string gpu_key = {}) {
  if (gpu_key.empty()) gpu_key = key;
  if (v.backend == neuflow::model::Backend::vulkan) {
    if (!is_fp16(v)) {
      g_vulkan_fp32_ms[gpu_key] = state.counters["ms"];
    } else if (const auto it = g_vulkan_fp32_ms.find(gpu_key);
               it != g_vulkan_fp32_ms.end() && state.counters["ms"] > 0) {
      state.counters["fp32_ms"] = it->second;
      state.counters["x_fp32"] = it->second / state.counters["ms"];
    }
  }
  if (v.backend == neuflow::model::Backend::cpu && v.convolution == neuflow::model::CpuConvolution::direct) {
    g_direct_ms[key] = state.counters["ms"];
  } else if (v.backend == neuflow::model::Backend::cpu) {
    g_cpu_ms[key] = state.counters["ms"];
    if (const auto it = g_direct_ms.find(key); it != g_direct_ms.end() && state.counters["ms"] > 0) {
      state.counters["direct_ms"] = it->second;
      state.counters["x_direct"] = it->second / state.counters["ms"];
    }
  } else if (const auto it = g_cpu_ms.find(key); it != g_cpu_ms.end() && state.counters["ms"] > 0) {
    state.counters["cpu_ms"] = it->second;
    state.counters["x_cpu"] = it->second / state.counters["ms"];
  }
}

std::map<std::string, double> g_vulkan_push_ms;  // "fp32/768x432" → vulkan_stream's ms a frame

void BM_Pair(benchmark::State& state, int width, int height, Variant variant) {
  FlowSession session(g_model, options_for(variant));
  const FrameSequence frames(width, height);
  session.compute(view(frames.at(0)), view(frames.at(1)));  // warm-up: primitives and buffers
  if (variant.backend != neuflow::model::Backend::cpu && !label_gpu_run(state, session, variant)) return;
  double total = 0;
  std::size_t i = 0;
  for (auto _ : state) {
    const cv::Mat frame0 = frames.at(i), frame1 = frames.at(i + 1);
    const auto t0 = std::chrono::steady_clock::now();
    auto f = session.compute(view(frame0), view(frame1));
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(f.uv.data());
    ++i;
  }
  report(state, total / static_cast<double>(state.iterations()), neuflow::model::network_cost(height, width).pair());
  compare(state, "pair/" + std::to_string(width) + "x" + std::to_string(height), variant);
}

// Pushes frame i of the sequence; the seconds the push took.
double timed_push(FlowSession& session, const FrameSequence& frames, std::size_t i) {
  const cv::Mat frame = frames.at(i);
  const auto t0 = std::chrono::steady_clock::now();
  auto f = session.push(view(frame));
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  benchmark::DoNotOptimize(f);
  return seconds;
}

void BM_Stream(benchmark::State& state, int width, int height, Variant variant) {
  FlowSession session(g_model, options_for(variant));
  const FrameSequence frames(width, height);
  session.push(view(frames.at(0)));
  session.push(view(frames.at(1)));  // warm-up
  if (variant.backend != neuflow::model::Backend::cpu && !label_gpu_run(state, session, variant)) return;
  double total = 0;
  std::size_t i = 2;
  for (auto _ : state) total += timed_push(session, frames, i++);
  report(state, total / static_cast<double>(state.iterations()),
         neuflow::model::network_cost(height, width).stream_frame());
  if (variant.backend == neuflow::model::Backend::vulkan)
    neuflow::bench::add_work_counters(state, session.device_work());
  compare(state, "stream/" + std::to_string(width) + "x" + std::to_string(height), variant);
  if (variant.backend == neuflow::model::Backend::vulkan) {
    g_vulkan_push_ms[std::string(neuflow::model::precision_name(variant.precision)) + "/" + std::to_string(width) +
                     "x" + std::to_string(height)] = state.counters["ms"];
  }
}

// A stream with a frame always in flight (FlowSession::submit/take, the element's way when
// frames queue): each frame goes up through the staging ring while the pair before it
// computes. x_push: vulkan_stream's time (push, nothing in flight) over this one's.
void BM_StreamPipelined(benchmark::State& state, int width, int height, Variant variant) {
  FlowSession session(g_model, options_for(variant));
  const FrameSequence frames(width, height);
  std::size_t i = 0;
  for (; i < 4; ++i) {  // warm-up: both ring entries' recordings, with and without a pair
    if (session.in_flight() == session.max_in_flight()) session.take();
    session.submit(view(frames.at(i)));
  }
  while (session.in_flight() > 1) session.take();
  if (!label_gpu_run(state, session, variant)) {
    while (session.in_flight() > 0) session.take();
    return;
  }
  state.SetLabel(session.backend_description() + ", " + std::to_string(session.max_in_flight()) + " in flight");
  double total = 0;
  for (auto _ : state) {
    const cv::Mat frame = frames.at(i);
    const auto t0 = std::chrono::steady_clock::now();
    session.submit(view(frame));  // goes up while the frame before it computes
    auto f = session.take();      // the frame before it
    total += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    benchmark::DoNotOptimize(f);
    ++i;
  }
  const neuflow::model::DeviceWork work = session.device_work();  // of a frame with one in flight
  while (session.in_flight() > 0) session.take();
  neuflow::bench::add_work_counters(state, work);
  if (g_config.work_tables) {
    neuflow::bench::print_work_table(stdout,
                                     gpu_prefix(variant.precision) + "stream_pipelined/" + std::to_string(width) + "x" +
                                         std::to_string(height) + ", " + session.backend_description(),
                                     work);
  }
  report(state, total / static_cast<double>(state.iterations()),
         neuflow::model::network_cost(height, width).stream_frame());
  const std::string key = std::to_string(width) + "x" + std::to_string(height);
  const auto push = g_vulkan_push_ms.find(std::string(neuflow::model::precision_name(variant.precision)) + "/" + key);
  if (push != g_vulkan_push_ms.end() && state.counters["ms"] > 0) {
    state.counters["push_ms"] = push->second;
    state.counters["x_push"] = push->second / state.counters["ms"];
  }
  compare(state, "stream/" + key, variant, "stream_pipelined/" + key);
}

// The stages the per-stage benchmarks report (refinement iterations summed per scale).
std::string stage_group(const std::string& name) {
  namespace stage = neuflow::model::stage;
  for (const std::string_view scale : {stage::scale_s8, stage::scale_s16}) {
    if (name.starts_with(stage::refine_prefix(scale)) || name.starts_with(stage::corr_prefix(scale))) {
      return "refine_" + std::string(scale);
    }
  }
  if (name == stage::backbone_s16 || name == stage::backbone_s8 || name == stage::conv_s8) return "encode";
  if (name == stage::merge_s8 || name == stage::context_merge_s8) return std::string(stage::merge_s8);
  if (name == stage::flow) return "upsample";
  return name;
}

std::map<std::string, std::map<std::string, double>> g_cpu_stage_ms;  // size → stage → ms

// Where a streamed frame's time goes: the observer is called at the end of each stage, so the
// time between consecutive calls is the stage's.
void BM_StreamStages(benchmark::State& state, int width, int height, Variant variant) {
  FlowSession session(g_model, options_for(variant));
  const FrameSequence frames(width, height);
  std::map<std::string, double> stage_seconds;
  auto last = std::chrono::steady_clock::now();
  const auto group = stage_group;
  session.set_observer([&](const neuflow::model::StageTensor& t) {
    const auto now = std::chrono::steady_clock::now();
    stage_seconds[group(t.name)] += std::chrono::duration<double>(now - last).count();
    last = now;
  });
  session.push(view(frames.at(0)));
  std::size_t i = 1;
  for (auto _ : state) {
    const cv::Mat frame = frames.at(i);
    last = std::chrono::steady_clock::now();
    auto f = session.push(view(frame));
    stage_seconds["restore"] += std::chrono::duration<double>(std::chrono::steady_clock::now() - last).count();
    benchmark::DoNotOptimize(f);
    ++i;
  }
  const std::string size = std::to_string(width) + "x" + std::to_string(height);
  for (const auto& [name, seconds] : stage_seconds) {
    const double ms = seconds * 1e3 / static_cast<double>(state.iterations());
    state.counters[name + "_ms"] = ms;
    if (variant.convolution == neuflow::model::CpuConvolution::automatic) g_cpu_stage_ms[size][name] = ms;
  }
}

// The same on a GPU, from its own timestamps (FlowSession::device_stage_times(), no
// read-back): each stage's device time, `device_ms` their sum, `host_ms` the whole push as
// the caller waits for it (upload, submission, read-back and the CPU's frame conversion too),
// and x_cpu_STAGE the CPU's time for that stage in this run over the GPU's.
void BM_VulkanStreamStages(benchmark::State& state, int width, int height, Variant variant) {
  FlowSession session(g_model, options_for(variant));
  const FrameSequence frames(width, height);
  session.push(view(frames.at(0)));
  session.push(view(frames.at(1)));  // warm-up: records the command buffers
  if (!label_gpu_run(state, session, variant)) return;
  if (session.device_stage_times().empty()) {
    state.SkipWithError("this device's compute queue has no timestamps (`neuflow devices`)");
    return;
  }
  std::map<std::string, double> stage_ms;
  double host_seconds = 0;
  std::size_t i = 2;
  for (auto _ : state) {
    host_seconds += timed_push(session, frames, i);
    for (const auto& t : session.device_stage_times()) stage_ms[stage_group(t.name)] += t.milliseconds;
    ++i;
  }
  const double n = static_cast<double>(state.iterations());
  const auto& cpu = g_cpu_stage_ms[std::to_string(width) + "x" + std::to_string(height)];
  double device_ms = 0;
  for (const auto& [name, total] : stage_ms) {
    const double ms = total / n;
    device_ms += ms;
    state.counters[name + "_ms"] = ms;
    if (const auto it = cpu.find(name); it != cpu.end() && ms > 0) state.counters["x_cpu_" + name] = it->second / ms;
  }
  state.counters["device_ms"] = device_ms;
  state.counters["host_ms"] = host_seconds * 1e3 / n;
}

// The whole of `text` as an int, or nothing.
std::optional<int> parse_int(const std::string& text) {
  int value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || error != std::errc() || stop != end) return std::nullopt;
  return value;
}

// An integer option's value that `check` accepts; nothing, once the reason is printed, else.
std::optional<int> int_option(const char* name, const std::string& value, std::optional<std::string> (*check)(int)) {
  const auto number = parse_int(value);
  const auto problem = number ? check(*number) : std::optional<std::string>("expected a whole number");
  if (!problem) return number;
  std::fprintf(stderr, "neuflow-bench-core: %s '%s': %s\n", name, value.c_str(), problem->c_str());
  return std::nullopt;
}

// Our own options are taken out of argv before Google Benchmark sees the rest.
bool take_option(int& argc, char** argv, const char* name, std::string& value) {
  const std::size_t len = std::strlen(name);
  for (int i = 1; i < argc; ++i) {
    std::string arg = argv[i];
    int consumed = 0;
    if (arg == name && i + 1 < argc) {
      value = argv[i + 1];
      consumed = 2;
    } else if (arg.compare(0, len + 1, std::string(name) + "=") == 0) {
      value = arg.substr(len + 1);
      consumed = 1;
    }
    if (consumed) {
      for (int j = i; j + consumed < argc; ++j) argv[j] = argv[j + consumed];
      argc -= consumed;
      return true;
    }
  }
  return false;
}

}  // namespace

int main(int argc, char** argv) {
  const char* shared_env = std::getenv("NEUFLOW_SHARED_DIR");
  const std::filesystem::path shared = shared_env && *shared_env ? shared_env : NEUFLOW_DEFAULT_SHARED_DIR;
  g_config.model = shared / "fixtures/neuflow-v2-seed0/checkpoint.pth";
  if (const char* env = std::getenv("NEUFLOW_MODEL"); env && *env) g_config.model = env;
  g_config.frames = shared / "fixtures/frames";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--help") == 0 || std::strcmp(argv[i], "-h") == 0) {
      std::printf("%s", kUsage);  // then Google Benchmark's own flags
      break;
    }
  }
  std::string value;
  if (take_option(argc, argv, "--model", value)) g_config.model = value;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--work") == 0) {
      g_config.work_tables = true;
      for (int j = i; j + 1 < argc; ++j) argv[j] = argv[j + 1];
      --argc;
      break;
    }
  }
  if (take_option(argc, argv, "--frames", value)) g_config.frames = value;
  if (take_option(argc, argv, "--threads", value)) {
    const auto threads = int_option("--threads", value, neuflow::model::check_threads);
    if (!threads) return 64;
    g_config.threads = *threads;
  }
  if (take_option(argc, argv, "--backend", value)) {
    if (value != "cpu" && value != "vulkan") {
      std::fprintf(
          stderr,
          "neuflow-bench-core: --backend wants cpu or vulkan (vulkan also runs the CPU, to compare), got '%s'\n",
          value.c_str());
      return 64;
    }
    g_config.vulkan = value == "vulkan";
  }
  if (take_option(argc, argv, "--device", value)) {
    const auto device = int_option("--device", value, neuflow::model::check_device);
    if (!device) return 64;
    g_config.device = *device;
  }
  if (take_option(argc, argv, "--precision", value)) {
    g_config.precisions.clear();
    for (std::size_t pos = 0; pos <= value.size();) {
      const std::size_t comma = std::min(value.find(',', pos), value.size());
      const auto precision = neuflow::model::parse_precision(value.substr(pos, comma - pos));
      if (!precision) {
        std::fprintf(stderr, "neuflow-bench-core: --precision wants fp32, fp16 or fp32,fp16, got '%s'\n",
                     value.c_str());
        return 64;
      }
      g_config.precisions.push_back(*precision);
      pos = comma + 1;
    }
    // fp32 first, so that each fp16 benchmark finds the fp32 time it is set against.
    std::sort(g_config.precisions.begin(), g_config.precisions.end());
    g_config.precisions.erase(std::unique(g_config.precisions.begin(), g_config.precisions.end()),
                              g_config.precisions.end());
  }
  if (take_option(argc, argv, "--sizes", value)) {
    g_config.sizes.clear();
    for (std::size_t pos = 0; pos < value.size();) {
      const std::size_t comma = std::min(value.find(',', pos), value.size());
      int w = 0, h = 0;
      if (std::sscanf(value.substr(pos, comma - pos).c_str(), "%dx%d", &w, &h) != 2) {
        std::fprintf(stderr, "neuflow-bench-core: --sizes wants WxH[,WxH...], got '%s'\n", value.c_str());
        return 64;
      }
      g_config.sizes.emplace_back(w, h);
      pos = comma + 1;
    }
  }
  try {
    g_model = FlowModel::load(g_config.model);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow-bench-core: %s\n(pass --model CKPT or set NEUFLOW_SHARED_DIR)\n", e.what());
    return 66;
  }

  benchmark::RegisterBenchmark("sgemm_peak/2048", BM_SgemmPeak)
      ->Arg(2048)
      ->Iterations(8)
      ->Unit(benchmark::kMillisecond);
  for (const auto& [w, h] : g_config.sizes) {
    const std::string size = std::to_string(w) + "x" + std::to_string(h);
    using neuflow::model::Backend;
    using neuflow::model::CpuConvolution;
    const Variant direct{Backend::cpu, CpuConvolution::direct}, cpu{Backend::cpu, CpuConvolution::automatic};
    // Whole frames: timed for at least 2 s each; stage breakdowns: three frames each.
    const auto timed = [w = w, h = h](const std::string& name, auto run, const Variant& variant) {
      benchmark::RegisterBenchmark(name.c_str(), run, w, h, variant)->Unit(benchmark::kMillisecond)->MinTime(2.0);
    };
    const auto staged = [w = w, h = h](const std::string& name, auto run, const Variant& variant) {
      benchmark::RegisterBenchmark(name.c_str(), run, w, h, variant)->Unit(benchmark::kMillisecond)->Iterations(3);
    };
    for (const char* mode : {"pair", "stream"}) {
      const auto run = std::string(mode) == "pair" ? BM_Pair : BM_Stream;
      timed("direct_" + std::string(mode) + "/" + size, run, direct);
      timed(std::string(mode) + "/" + size, run, cpu);
    }
    // Lavapipe (Vulkan on the CPU) runs these too, but its times say nothing of a GPU's.
    const auto gpu_precisions = g_config.vulkan ? g_config.precisions : std::vector<neuflow::model::Precision>{};
    for (const auto precision : gpu_precisions) {
      const Variant vulkan{Backend::vulkan, CpuConvolution::automatic, precision};
      const std::string prefix = gpu_prefix(precision);
      // Timed by the wall clock: the host thread's CPU time is the submissions' alone, so
      // MinTime by CPU time ran a 10 s lavapipe frame ten times.
      using Run = void (*)(benchmark::State&, int, int, Variant);
      for (const auto& [mode, run] :
           {std::pair<const char*, Run>{"pair/", BM_Pair}, std::pair<const char*, Run>{"stream/", BM_Stream},
            std::pair<const char*, Run>{"stream_pipelined/", BM_StreamPipelined}}) {
        benchmark::RegisterBenchmark((prefix + mode + size).c_str(), run, w, h, vulkan)
            ->Unit(benchmark::kMillisecond)
            ->MinTime(2.0)
            ->UseRealTime();
      }
    }
    staged("direct_stream_stages/" + size, BM_StreamStages, direct);
    staged("stream_stages/" + size, BM_StreamStages, cpu);
    for (const auto precision : gpu_precisions) {
      staged(gpu_prefix(precision) + "stream_stages/" + size, BM_VulkanStreamStages,
             Variant{Backend::vulkan, CpuConvolution::automatic, precision});
    }
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 64;
  std::printf("threads: %d, model: %s\n", g_config.threads, g_config.model.string().c_str());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
