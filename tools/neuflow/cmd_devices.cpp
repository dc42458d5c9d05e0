// `neuflow devices`: the Vulkan devices a session can run on (--backend vulkan --device N).
#include <cstdio>

#include "commands.hpp"
#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::cli {

namespace {

void run_devices() {
  std::vector<model::GpuDevice> devices;
  try {
    devices = model::list_gpu_devices();
  } catch (const model::BackendError& e) {
    throw CommandError(kExitUnavailable, std::string("devices: ") + e.what());
  }
  if (devices.empty()) {
    throw CommandError(kExitUnavailable,
                       "devices: Vulkan found no device (install the GPU's Vulkan driver, or "
                       "mesa-vulkan-drivers for lavapipe on the CPU)");
  }
  int first_gpu = -1;
  for (const auto& d : devices) {
    if (first_gpu < 0 && d.is_gpu()) first_gpu = d.index;
  }
  for (const auto& d : devices) {
    std::printf("%d: %s\n", d.index, d.name.c_str());
    std::printf("   type: %s%s\n", d.type.c_str(),
                d.index == first_gpu ? " (what --backend auto uses)"
                : d.is_gpu()         ? ""
                                     : " (not a GPU: only --backend vulkan uses it)");
    std::printf("   Vulkan %s, %s\n", d.api_version.c_str(), d.driver.c_str());
    std::printf("   memory: %llu MiB device-local, at most %llu MiB per buffer\n",
                static_cast<unsigned long long>(d.memory_bytes >> 20),
                static_cast<unsigned long long>(d.max_buffer_bytes >> 20));
    std::printf("   fp16: %s\n", d.fp16 ? "yes (shaderFloat16, 16-bit storage)" : "no");
    std::printf("   tensor cores: %s\n", d.tensor_cores ? "yes (VK_NV_cooperative_matrix, fp16 products)" : "no");
    std::printf("   stage timestamps: %s\n", d.timestamps ? "yes (neuflow-bench-core's vulkan_stream_stages)" : "no");
  }
  if (first_gpu < 0) std::printf("no GPU: --backend auto runs on the CPU\n");
}

}  // namespace

void register_devices(CLI::App& app) {
  auto* cmd = app.add_subcommand("devices", "List the Vulkan devices the network can run on");
  cmd->callback([] { run_devices(); });
}

}  // namespace neuflow::cli
