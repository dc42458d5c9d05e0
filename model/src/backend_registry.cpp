#include "backend_registry.hpp"

#include <utility>

#include "neuflow/model/gpu_devices.hpp"
#include "vulkan/vulkan_backend.hpp"

namespace neuflow::model {

BackendRegistry::BackendRegistry(std::shared_ptr<const FlowModel> model, const SessionOptions& options)
    : model_(std::move(model)), options_(options) {
  if (options_.backend == Backend::vulkan) {
    vulkan_ = open_vulkan(model_, options_.device, options_.precision, fallback_);
  } else if (options_.backend == Backend::automatic) {
    if (const int gpu = find_gpu_for_auto(options_.device); gpu >= 0) {
      try {
        vulkan_ = open_vulkan(model_, gpu, options_.precision, fallback_);
      } catch (const BackendError& e) {
        leave_for_cpu(e.what());
      }
    } else if (options_.device >= 0) {
      leave_for_cpu("no Vulkan device " + std::to_string(options_.device) + " (`neuflow devices` lists them)");
    }
  }
  if (vulkan_) description_ = describe(*vulkan_);
}

BackendRegistry::~BackendRegistry() = default;

void BackendRegistry::leave_for_cpu(const std::string& why) {
  fallback_ = "backend auto: " + why + "; running on the CPU instead";
  vulkan_.reset();
  description_ = "cpu";
}

std::unique_ptr<InferenceBackend> BackendRegistry::make(int height, int width) {
  if (vulkan_) {
    try {
      return make_vulkan_backend(vulkan_, height, width);
    } catch (const BackendError& e) {
      if (options_.backend != Backend::automatic) throw;
      leave_for_cpu(e.what());
    }
  }
  return make_cpu_backend(*model_, height, width, options_.cpu_convolution);
}

int BackendRegistry::stream_depth() const { return vulkan_ ? kVulkanStreamDepth : 1; }

}  // namespace neuflow::model
