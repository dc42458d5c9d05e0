// Each stride-1 3×3 convolution of NeuFlow-V2 at its real shape for one model size, computed
// by oneDNN's direct convolution and by Winograd F(4×4, 3×3), in the same run: the table from
// which the CPU backend chooses per layer (model/src/cpu/dnnl/conv_op.cpp). Times are the
// best of several runs; GFLOP/s counts the direct convolution's arithmetic for both, so
// Winograd's figure can exceed the sgemm peak measured first.
//
//   neuflow-bench-conv [--size 768x432] [--threads 2] [--runs 10]
#include <oneapi/dnnl/dnnl.h>
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "dnnl/context.hpp"
#include "dnnl/conv_op.hpp"
#include "neuflow/model/architecture.hpp"

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
  const double s = best_seconds(runs, [&] { dnnl_sgemm('N', 'N', n, n, n, 1.f, a.data(), n, b.data(), n, 0.f, c.data(), n); });
  return 2.0 * n * n * n / s / 1e9;
}

struct Layer {
  std::string name;
  int in, out, scale;
};

// Times one layer's convolution computed as `choice` says, its input in `layout`.
double time_conv(const ConvWeights& w, int h, int width, CpuConvolution choice, tag layout, int runs) {
  PlanContext context{{}, choice};
  const dnnl::memory::desc in_desc({1, w.in_channels, h, width}, dnnl::memory::data_type::f32, layout);
  ConvOp op(w, {1, 1, Activation::leaky_relu}, in_desc, context);
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

}  // namespace

int main(int argc, char** argv) {
  int width = 768, height = 432, threads = 2, runs = 10;
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--size") && std::sscanf(argv[i + 1], "%dx%d", &width, &height) == 2) continue;
    if (!std::strcmp(argv[i], "--threads")) { threads = std::stoi(argv[i + 1]); continue; }
    if (!std::strcmp(argv[i], "--runs")) { runs = std::stoi(argv[i + 1]); continue; }
    std::fprintf(stderr, "usage: neuflow-bench-conv [--size WxH] [--threads N] [--runs N]\n");
    return 64;
  }
  omp_set_num_threads(threads);
  const double peak = sgemm_peak_gflops(runs);
  std::printf("size %dx%d, threads %d, sgemm peak %.1f GFLOP/s\n", width, height, threads, peak);
  std::printf("%-36s %5s %5s %9s %9s %9s %8s %8s %7s\n", "layer", "in", "out", "HxW", "direct_ms", "wino_ms",
              "direct", "wino", "x_direct");
  std::vector<Layer> layers;
  for (const auto& l : neuflow_v2_layers()) {
    if (l.kind == LayerKind::conv && l.kernel == 3) layers.push_back({l.name, l.in, l.out, l.scale});
  }
  // The refinements' first convolution runs as two: the per-iteration inputs and the per-pair constant ones.
  layers.push_back({"refine_s8.conv1 (per iteration)", 147, 128, 8});
  layers.push_back({"refine_s8.conv1 (per pair)", 65, 128, 8});
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-0.05f, 0.05f);
  for (const auto& l : layers) {
    const int h = height / l.scale, w = width / l.scale;
    ConvWeights weights{l.out, l.in, 3, 3, std::vector<float>(static_cast<std::size_t>(l.out) * l.in * 9), {}};
    for (auto& v : weights.weight) v = u(rng);
    const double direct = time_conv(weights, h, w, CpuConvolution::direct, tag::nChw16c, runs);
    const double wino = time_conv(weights, h, w, CpuConvolution::winograd, tag::nChw8c, runs);
    const double flops = 2.0 * h * w * l.in * l.out * 9;
    char hw[32];
    std::snprintf(hw, sizeof hw, "%dx%d", h, w);
    std::printf("%-36s %5d %5d %9s %9.3f %9.3f %8.1f %8.1f %7.2f\n", l.name.c_str(), l.in, l.out, hw, direct * 1e3,
                wino * 1e3, flops / direct / 1e9, flops / wino / 1e9, direct / wino);
  }
  return 0;
}
