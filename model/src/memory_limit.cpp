#include "memory_limit.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "graph/memory_plan.hpp"
#include "graph/network_graph.hpp"
#include "inference_backend.hpp"

namespace neuflow::model {

namespace {

// The largest score block a backend holds (the Vulkan backend's: 8 Mi floats).
constexpr int kScoreBlockFloats = 8 << 20;
constexpr std::size_t kMiB = std::size_t{1} << 20;

std::string megabytes(std::size_t bytes) { return std::to_string((bytes + kMiB - 1) / kMiB) + " MiB"; }

}  // namespace

std::size_t estimate_plan_bytes(const NetworkWeights& weights, int model_height, int model_width) {
  const int tokens = std::max((model_height / 16) * (model_width / 16), 1);
  const auto g = graph::build_network_graph<std::vector<float>>(weights, model_height, model_width, Iterations{},
                                                                std::clamp(kScoreBlockFloats / tokens, 1, tokens));
  const graph::LiveRanges ranges = graph::live_ranges<std::vector<float>>(g.tensors, {&g.encode, &g.flow});
  std::vector<std::size_t> bytes(g.tensors.size(), 0);
  std::size_t fixed = 0;
  for (std::size_t t = 0; t < g.tensors.size(); ++t) {
    const graph::TensorDesc& d = g.tensors.descs()[t];
    const std::size_t size = d.count() * sizeof(float);
    if (d.storage == graph::Storage::transient) {
      bytes[t] = size;
    } else if (d.storage == graph::Storage::persistent) {
      fixed += size;
    } else if (d.role == graph::FrameRole::encoded) {
      fixed += size * InferenceBackend::kSlots;
    }
  }
  const std::size_t transient = graph::plan_offsets(bytes, ranges, 64).size;
  const std::size_t flow = std::size_t{2} * sizeof(float) * static_cast<std::size_t>(model_height) * model_width;
  return transient + transient / 3 + fixed + flow;
}

std::optional<std::size_t> memory_limit_bytes(int max_memory_mb) {
  if (max_memory_mb > 0) return static_cast<std::size_t>(max_memory_mb) * kMiB;
  std::ifstream meminfo("/proc/meminfo");
  for (std::string line; std::getline(meminfo, line);) {
    std::istringstream fields(line);
    std::string key;
    std::size_t kib = 0;
    if (fields >> key >> kib && key == "MemAvailable:") return kib * 1024 / 4 * 3;
  }
  return std::nullopt;
}

std::optional<std::string> memory_problem(const NetworkWeights& weights, const SessionOptions& options,
                                          int model_height, int model_width) {
  const std::optional<std::size_t> limit = memory_limit_bytes(options.max_memory_mb);
  if (!limit) return std::nullopt;
  const std::size_t need = estimate_plan_bytes(weights, model_height, model_width);
  if (need <= *limit) return std::nullopt;
  return "a " + std::to_string(model_width) + "x" + std::to_string(model_height) + " model size needs about " +
         megabytes(need) + ", more than the " + megabytes(*limit) +
         (options.max_memory_mb > 0 ? " max-memory allows"
                                    : " max-memory allows (three quarters of the available memory)") +
         ": set model-width and model-height to run the network smaller, or raise max-memory";
}

}  // namespace neuflow::model
