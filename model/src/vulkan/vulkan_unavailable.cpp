// Linked instead of the Vulkan backend when the project is configured with NEUFLOW_VULKAN=OFF.
#include "neuflow/model/gpu_devices.hpp"
#include "vulkan/vulkan_backend.hpp"

namespace neuflow::model {

namespace {
[[noreturn]] void unavailable() {
  throw BackendError(BackendError::Kind::unavailable,
                     "this build of neuflow has no Vulkan backend (configured with -DNEUFLOW_VULKAN=OFF)");
}
}  // namespace

struct VulkanContext {};

std::shared_ptr<VulkanContext> open_vulkan(const std::shared_ptr<const FlowModel>&, int, Precision, std::string&) {
  unavailable();
}
std::string describe(const VulkanContext&) { return "vulkan"; }
std::unique_ptr<InferenceBackend> make_vulkan_backend(const std::shared_ptr<VulkanContext>&, int, int) {
  unavailable();
}
int find_gpu_for_auto(int) { return -1; }

}  // namespace neuflow::model
