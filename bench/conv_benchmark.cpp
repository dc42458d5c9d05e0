// Each convolution of NeuFlow-V2 that Winograd can compute (the stride-1 3×3 ones and the 6×6
// stride-2 one on 192 channels) at its real shape for one model size, computed
// by oneDNN's direct convolution and by Winograd F(4×4, 3×3) and F(6×6, 3×3), in the same
// run: the table from which the CPU backend chooses per layer (model/src/cpu/dnnl/conv_op.cpp,
// WinogradConv::faster_tile). Times are the best of several runs; GFLOP/s counts the direct
// convolution's arithmetic for both, so Winograd's figure can exceed the sgemm peak measured
// first.
//
// With --arena, instead: the CPU plan's memory at that size, in MB and bytes per model pixel,
// for both ways of computing the convolutions: its one allocation (the graph's tensors and the
// ops' scratch, placed from their live ranges) and the largest scratch of one op within it.
//
//   neuflow-bench-conv [--size 768x432] [--threads 2] [--runs 10] [--arena [--model CKPT]]
#include <omp.h>
#include <oneapi/dnnl/dnnl.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "dnnl/context.hpp"
#include "dnnl/conv_op.hpp"
#include "network.hpp"
#include "neuflow/model/architecture.hpp"
#include "neuflow/model/flow_model.hpp"
#include "winograd/winograd_conv.hpp"

namespace {

using namespace neuflow::model;
using tag = dnnl::memory::format_tag;

template <typename F>
double best_seconds(int runs, F&& f) {
  f();  // warm-up
  double best = 1e30;
  for (int i = 0; i < runs; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  return best;
}

double sgemm_peak_gflops(int runs) {
  const int n = 2048;
  std::vector<float> a(static_cast<std::size_t>(n) * n, 1.f), b(a.size(), 0.5f), c(a.size());
  const double s =
      best_seconds(runs, [&] { dnnl_sgemm('N', 'N', n, n, n, 1.f, a.data(), n, b.data(), n, 0.f, c.data(), n); });
  return 2.0 * n * n * n / s / 1e9;
}

struct Layer {
  std::string name;
  int in, out, scale;  // scale: the output's
  int stride = 1;      // kernel 3·stride, padding stride
};

// Times one layer's convolution computed as `choice` says, its input (h × width) in `layout`.
double time_conv(const ConvWeights& w, int stride, int h, int width, CpuConvolution choice, tag layout, int runs) {
  PlanContext context{{}, choice};
  const dnnl::memory::desc in_desc({1, w.in_channels, h, width}, dnnl::memory::data_type::f32, layout);
  ConvOp op(w, {stride, stride, Activation::leaky_relu}, in_desc, context);
  dnnl::memory input = context.arena.make(in_desc);
  context.arena.finalize();
  std::memset(input.get_data_handle(), 0, in_desc.get_size());
  auto* data = static_cast<float*>(input.get_data_handle());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-1.f, 1.f);
  for (std::size_t i = 0; i < in_desc.get_size() / sizeof(float); ++i) data[i] = u(rng);
  dnnl::stream stream(cpu_engine());
  return best_seconds(runs, [&] {
    op.run(stream, input);
    stream.wait();
  });
}

int print_arena(const std::string& model_path, int width, int height) {
  std::shared_ptr<const FlowModel> model;
  try {
    model = FlowModel::load(model_path);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow-bench-conv: %s\n(pass --model CKPT or set NEUFLOW_SHARED_DIR)\n", e.what());
    return 66;
  }
  const double pixels = static_cast<double>(width) * height;
  std::printf("memory at %dx%d (%.2f Mpixel), MB and bytes per pixel\n", width, height, pixels / 1e6);
  std::printf("%-10s %8s %8s %8s %8s\n", "", "direct", "B/px", "winograd", "B/px");
  const NetworkPlan direct(model->weights(), height, width, CpuConvolution::direct);
  const NetworkPlan winograd(model->weights(), height, width, CpuConvolution::winograd);
  const auto row = [&](const char* name, double d, double w) {
    std::printf("%-10s %8.1f %8.0f %8.1f %8.0f\n", name, d / 1e6, d / pixels, w / 1e6, w / pixels);
  };
  const NetworkPlan::Memory d = direct.memory(), w = winograd.memory();
  row("allocation", static_cast<double>(d.allocation), static_cast<double>(w.allocation));
  row("op scratch", static_cast<double>(d.largest_scratch), static_cast<double>(w.largest_scratch));
  return 0;
}

int run(int argc, char** argv) {
  int width = 768, height = 432, threads = 2, runs = 10;
  bool arena = false;
  const char* shared_env = std::getenv("NEUFLOW_SHARED_DIR");
  std::string model = std::string(shared_env && *shared_env ? shared_env : NEUFLOW_DEFAULT_SHARED_DIR) +
                      "/fixtures/neuflow-v2-seed0/checkpoint.pth";
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--arena")) {
      arena = true;
      continue;
    }
    if (i + 1 < argc && !std::strcmp(argv[i], "--size") && std::sscanf(argv[i + 1], "%dx%d", &width, &height) == 2) {
      ++i;
      continue;
    }
    if (i + 1 < argc && !std::strcmp(argv[i], "--threads")) {
      threads = std::stoi(argv[++i]);
      continue;
    }
    if (i + 1 < argc && !std::strcmp(argv[i], "--runs")) {
      runs = std::stoi(argv[++i]);
      continue;
    }
    if (i + 1 < argc && !std::strcmp(argv[i], "--model")) {
      model = argv[++i];
      continue;
    }
    std::fprintf(stderr, "usage: neuflow-bench-conv [--size WxH] [--threads N] [--runs N] [--arena [--model CKPT]]\n");
    return 64;
  }
  omp_set_num_threads(threads);
  if (arena) return print_arena(model, width, height);
  const double peak = sgemm_peak_gflops(runs);
  std::printf("size %dx%d, threads %d, sgemm peak %.1f GFLOP/s\n", width, height, threads, peak);
  // f4_ms, f6_ms: Winograd F(4×4) and F(6×6) on the layer; tile: the form the plan picks
  // (dnnl/conv_op.cpp), which the wino GFLOP/s and x_direct columns describe.
  std::printf("%-36s %5s %5s %9s %9s %8s %8s %4s %7s %7s %7s\n", "layer", "in", "out", "HxW", "direct_ms", "f4_ms",
              "f6_ms", "tile", "direct", "wino", "x_direct");
  std::vector<Layer> layers;
  for (const auto& l : neuflow_v2_layers()) {
    if (l.kind == LayerKind::conv && l.kernel == 3) layers.push_back({l.name, l.in, l.out, l.scale});
    // The backbone's 6×6 stride-2 convolution on 192 channels, by space-to-depth.
    if (l.kind == LayerKind::conv && l.kernel == 6 && l.in % 8 == 0)
      layers.push_back({l.name, l.in, l.out, l.scale, 2});
  }
  // The refinements' first convolution runs as two: the per-iteration inputs and the per-pair constant ones.
  layers.push_back({"refine_s8.conv1 (per iteration)", 147, 128, 8});
  layers.push_back({"refine_s8.conv1 (per pair)", 65, 128, 8});
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  for (const auto& l : layers) {
    const int h = height / l.scale, w = width / l.scale;
    const int k = 3 * l.stride, ih = h * l.stride, iw = w * l.stride;
    ConvWeights weights{l.out, l.in, k, k, std::vector<float>(static_cast<std::size_t>(l.out) * l.in * k * k), {}};
    for (auto& v : weights.weight) v = u(rng);
    const double direct = time_conv(weights, l.stride, ih, iw, CpuConvolution::direct, tag::nChw16c, runs);
    const double wino4 = time_conv(weights, l.stride, ih, iw, CpuConvolution::winograd4, tag::nChw8c, runs);
    const double wino6 = time_conv(weights, l.stride, ih, iw, CpuConvolution::winograd6, tag::nChw8c, runs);
    // The plan's choice: F(6×6) only on the 1/8 refinement's layers (ConvParams::repeated).
    const bool repeated = l.name.rfind("refine_s8", 0) == 0 && l.name != "refine_s8.conv1.conv" &&
                          l.name.find("(per pair)") == std::string::npos;
    const bool six =
        repeated && WinogradConv::faster_tile(l.in * l.stride * l.stride, l.out, h, w) == WinogradTile::f6x6;
    const double wino = six ? wino6 : wino4;
    const double flops = 2.0 * h * w * l.in * l.out * k * k;
    char hw[32];
    std::snprintf(hw, sizeof hw, "%dx%d", h, w);
    std::printf("%-36s %5d %5d %9s %9.3f %8.3f %8.3f %4s %7.1f %7.1f %7.2f\n", l.name.c_str(), l.in, l.out, hw,
                direct * 1e3, wino4 * 1e3, wino6 * 1e3, six ? "f6" : "f4", flops / direct / 1e9, flops / wino / 1e9,
                direct / wino);
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "neuflow-bench-conv: %s\n", e.what());
    return 70;
  }
}
