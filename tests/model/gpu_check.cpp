// neuflow-gpu-check: what scripts/gpu-check.sh runs on a machine with a GPU, from a build made
// elsewhere. It needs nothing but the Vulkan loader and the driver: the model is made here with
// random weights (as the fixture's were made), the frames are drawn here, so no fixture, image
// codec or test framework has to travel.
//
// Checks (each printed with its numbers; the exit status is 1 when one fails):
//  - the GPU's fp32 flow against the CPU's (the fixture tests' tolerances: 1e-2 px max, 1e-3 mean);
//  - fp16 with the scalar products against fp32, within the fp16 bound;
//  - where the GPU has tensor cores: their flow against their emulated twin's and against fp32,
//    within the same bound.
// Then one table: per size, precision and product kernels (and the products in 64×64 tiles,
// against their tiles chosen by the grid), a streamed frame's time (pipelined,
// frames in flight), a pair's, the GPU's own time of a frame (its timestamps), and what a frame
// asks of it (dispatches, barriers, GB moved, GMAC).
#include <stdlib.h>  // mkdtemp, setenv
#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "checkpoint_builder.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "support/flow_difference.hpp"

namespace neuflow::model {
namespace {

struct Size {
  int w = 0, h = 0;
};

// A textured BGR frame whose content moves by (dx, dy) px per frame index: smooth waves at
// several scales plus a fine pattern, so every level of the network sees structure.
std::vector<std::uint8_t> draw_frame(const Size& s, int index, double dx = 3.25, double dy = -1.75) {
  std::vector<std::uint8_t> bgr(static_cast<std::size_t>(s.w) * s.h * 3);
  for (int y = 0; y < s.h; ++y) {
    for (int x = 0; x < s.w; ++x) {
      const double u = x - dx * index, v = y - dy * index;
      for (int c = 0; c < 3; ++c) {
        const double value = 128 + 50 * std::sin(0.031 * u + 0.017 * v + c) +
                             30 * std::cos(0.007 * u - 0.023 * v * (c + 1)) +
                             20 * std::sin(0.41 * u) * std::cos(0.37 * v + c);
        bgr[(static_cast<std::size_t>(y) * s.w + x) * 3 + c] = static_cast<std::uint8_t>(std::clamp(value, 0.0, 255.0));
      }
    }
  }
  return bgr;
}

ImageView view(const std::vector<std::uint8_t>& bgr, const Size& s) {
  return ImageView{bgr.data(), s.w, s.h, static_cast<std::ptrdiff_t>(s.w) * 3, ChannelOrder::bgr};
}

// NEUFLOW_VULKAN_PRODUCTS (and the products' NEUFLOW_VULKAN_GEMM_TILE) for the sessions made
// while it lives.
class Products {
 public:
  explicit Products(const char* kernels, const char* tile = "auto") {
    setenv("NEUFLOW_VULKAN_PRODUCTS", kernels, 1);
    setenv("NEUFLOW_VULKAN_GEMM_TILE", tile, 1);
  }
  ~Products() {
    unsetenv("NEUFLOW_VULKAN_PRODUCTS");
    unsetenv("NEUFLOW_VULKAN_GEMM_TILE");
  }
  Products(const Products&) = delete;
  Products& operator=(const Products&) = delete;
};

using Difference = test::FlowDifference;

int failures = 0;

void report(const std::string& what, bool passed, const std::string& numbers) {
  std::printf("%s %s: %s\n", passed ? "PASS" : "FAIL", what.c_str(), numbers.c_str());
  if (!passed) ++failures;
}

void check_exact(const std::string& what, const Difference& d) {
  char text[160];
  std::snprintf(text, sizeof text, "max %.5f px, mean %.6f px (bounds 1e-2, 1e-3)", d.max, d.mean);
  report(what, d.max < 1e-2 && d.mean < 1e-3, text);
}

void check_fp16(const std::string& what, const Difference& d) {
  char text[200];
  std::snprintf(
      text, sizeof text,
      "mean EPE %.3f %% of the mean |flow| (%.2f px), max %.3f %% of the largest (%.2f px); bounds 0.5 %%, 1 %%",
      100 * d.epe / d.magnitude, d.magnitude, 100 * d.worst / d.largest, d.largest);
  report(what, d.epe < 0.005 * d.magnitude && d.worst < 0.01 * d.largest, text);
}

SessionOptions options(int device, Precision precision) {
  return {.backend = Backend::vulkan, .device = device, .precision = precision};
}

void check_parity(const std::shared_ptr<const FlowModel>& model, int device, const GpuDevice& gpu, const Size& s) {
  const auto f0 = draw_frame(s, 0), f1 = draw_frame(s, 1);
  const std::string at = " at " + std::to_string(s.w) + "x" + std::to_string(s.h);
  FlowSession cpu(model, {.backend = Backend::cpu});
  const flow::FlowField exact = cpu.compute(view(f0, s), view(f1, s));
  FlowSession fp32(model, options(device, Precision::fp32));
  const flow::FlowField gpu32 = fp32.compute(view(f0, s), view(f1, s));
  check_exact("vulkan fp32 vs cpu" + at, test::flow_difference(exact, gpu32));
  if (!gpu.fp16) return;
  {
    const Products scalar("scalar");
    FlowSession fp16(model, options(device, Precision::fp16));
    check_fp16("vulkan fp16 (scalar products) vs fp32" + at,
               test::flow_difference(gpu32, fp16.compute(view(f0, s), view(f1, s))));
  }
  if (!gpu.tensor_cores) return;
  FlowSession cores(model, options(device, Precision::fp16));
  const flow::FlowField real = cores.compute(view(f0, s), view(f1, s));
  check_fp16("tensor cores vs fp32" + at, test::flow_difference(gpu32, real));
  const Products twin("twin");
  FlowSession emulated(model, options(device, Precision::fp16));
  check_fp16("tensor cores vs their emulated twin" + at,
             test::flow_difference(emulated.compute(view(f0, s), view(f1, s)), real));
}

double milliseconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

// `tile`: the products' (NEUFLOW_VULKAN_GEMM_TILE); "auto" chooses by the grid.
void time_row(const std::shared_ptr<const FlowModel>& model, int device, const Size& s, Precision precision,
              const char* products, int frames, int pair_count, const char* tile = "auto") {
  const Products chosen(products, tile);
  FlowSession session(model, options(device, precision));
  std::vector<std::vector<std::uint8_t>> drawn(4);
  for (int i = 0; i < 4; ++i) drawn[static_cast<std::size_t>(i)] = draw_frame(s, i);
  // One pushed pair for the GPU's own time and the counts.
  session.push(view(drawn[0], s));
  session.push(view(drawn[1], s));
  double device_ms = 0;
  for (const auto& stage : session.device_stage_times()) device_ms += stage.milliseconds;
  const DeviceWork work = session.device_work();
  // Streamed, pipelined: as many frames in flight as the session keeps.
  session.reset();
  const int depth = session.max_in_flight();
  for (int i = 0; i < depth; ++i) session.submit(view(drawn[static_cast<std::size_t>(i % 4)], s));
  session.take();
  auto t0 = std::chrono::steady_clock::now();
  for (int i = 0; i < frames; ++i) {
    session.submit(view(drawn[static_cast<std::size_t>((i + depth) % 4)], s));
    session.take();
  }
  const double stream_ms = milliseconds_since(t0) / frames;
  while (session.in_flight() > 0) session.take();
  // Pairs: the median.
  std::vector<double> pairs;
  for (int i = 0; i < pair_count; ++i) {
    t0 = std::chrono::steady_clock::now();
    session.compute(view(drawn[0], s), view(drawn[1], s));
    pairs.push_back(milliseconds_since(t0));
  }
  std::sort(pairs.begin(), pairs.end());
  std::printf("| %4dx%-4d | %-4s | %-12s | %8.2f | %8.2f | %8.2f | %2d | %5d | %5d | %6.3f | %7.2f |\n", s.w, s.h,
              precision == Precision::fp16 ? "fp16" : "fp32",
              (std::string(products) + (std::string(tile) == "auto" ? "" : std::string(", ") + tile)).c_str(),
              stream_ms, pairs[pairs.size() / 2], device_ms, depth, work.dispatches, work.barriers,
              static_cast<double>(work.bytes_read() + work.bytes_written()) / 1e9,
              static_cast<double>(work.multiply_adds()) / 1e9);
}

std::optional<Size> parse_size(const std::string& text) {
  const auto x = text.find('x');
  if (x == std::string::npos) return std::nullopt;
  try {
    return Size{std::stoi(text.substr(0, x)), std::stoi(text.substr(x + 1))};
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

int run(int argc, char** argv) {
  CLI::App app{"The GPU's parity and throughput checks (scripts/gpu-check.sh)"};
  std::vector<std::string> sizes{"768x432", "1024x448"};
  std::string check_size = "768x432";
  int frames = 30, pairs = 5, device = -1;
  app.add_option("--sizes", sizes, "Sizes timed (WxH, multiples of 16)")->delimiter(',');
  app.add_option("--check-size", check_size, "Size the flows are compared at (WxH)");
  app.add_option("--frames", frames, "Streamed frames timed per row")->check(CLI::Range(1, 10000));
  app.add_option("--pairs", pairs, "Pairs timed per row (the median is printed)")->check(CLI::Range(1, 1000));
  app.add_option("--device", device, "Vulkan device (-1: the first GPU)");
  CLI11_PARSE(app, argc, argv);

  // No device: exit 77, which ctest reads as a skip, unless NEUFLOW_REQUIRE_VULKAN says one
  // must be there (CI, where lavapipe is installed).
  const char* required = std::getenv("NEUFLOW_REQUIRE_VULKAN");
  const int missing = required != nullptr && *required != '\0' && std::string(required) != "0" ? 2 : 77;
  std::vector<GpuDevice> devices;
  try {
    devices = list_gpu_devices();
  } catch (const BackendError& e) {
    std::fprintf(stderr, "neuflow-gpu-check: %s\n", e.what());
    return missing;
  }
  for (const auto& d : devices) {
    std::printf("device %d: %s (%s), Vulkan %s, %s, %llu MiB, fp16 %s, tensor cores %s\n", d.index, d.name.c_str(),
                d.type.c_str(), d.api_version.c_str(), d.driver.c_str(),
                static_cast<unsigned long long>(d.memory_bytes >> 20), d.fp16 ? "yes" : "no",
                d.tensor_cores ? "yes" : "no");
  }
  if (device < 0) {
    const auto gpu = std::find_if(devices.begin(), devices.end(), [](const GpuDevice& d) { return d.is_gpu(); });
    device = gpu != devices.end() ? gpu->index : 0;
  }
  if (devices.empty() || device >= static_cast<int>(devices.size())) {
    std::fprintf(stderr, "neuflow-gpu-check: no Vulkan device %d\n", device);
    return missing;
  }
  const GpuDevice& gpu = devices[static_cast<std::size_t>(device)];
  if (!gpu.is_gpu())
    std::printf("note: device %d is not a GPU (%s): its times say nothing of a GPU's\n", device, gpu.type.c_str());

  char folder_template[] = "/tmp/neuflow-gpu-check-XXXXXX";
  if (mkdtemp(folder_template) == nullptr) {
    std::perror("neuflow-gpu-check: mkdtemp");
    return 2;
  }
  const std::filesystem::path folder(folder_template);
  test::random_neuflow_checkpoint(0).write(folder / "random.pth");
  const auto model = FlowModel::load(folder / "random.pth");
  std::filesystem::remove_all(folder);

  const auto checked = parse_size(check_size);
  if (!checked) {
    std::fprintf(stderr, "neuflow-gpu-check: --check-size: expected WxH, got \"%s\"\n", check_size.c_str());
    return 2;
  }
  check_parity(model, device, gpu, *checked);

  std::printf(
      "\n| size | prec | products | stream ms/frame | pair ms | GPU ms/frame | in flight | dispatches | barriers | GB "
      "moved | GMAC |\n");
  std::printf("|---|---|---|---|---|---|---|---|---|---|---|\n");
  for (const auto& text : sizes) {
    const auto s = parse_size(text);
    if (!s) {
      std::fprintf(stderr, "neuflow-gpu-check: --sizes: expected WxH, got \"%s\"\n", text.c_str());
      return 2;
    }
    time_row(model, device, *s, Precision::fp32, "scalar", frames, pairs);
    // The products in the 64×64 tiles they all took before the tiles were chosen by the grid
    // (docs/benchmarks.md): what the choice is worth on this GPU.
    time_row(model, device, *s, Precision::fp32, "scalar", frames, pairs, "64");
    if (!gpu.fp16) continue;
    time_row(model, device, *s, Precision::fp16, "scalar", frames, pairs);
    if (gpu.tensor_cores) {
      time_row(model, device, *s, Precision::fp16, "tensor-cores", frames, pairs);
      time_row(model, device, *s, Precision::fp16, "tensor-cores", frames, pairs, "64");
    }
  }
  std::printf("\n%s: %d check(s) failed\n", failures == 0 ? "passed" : "FAILED", failures);
  return failures == 0 ? 0 : 1;
}

}  // namespace
}  // namespace neuflow::model

int main(int argc, char** argv) {
  try {
    return neuflow::model::run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow-gpu-check: %s\n", e.what());
    return 2;
  }
}
