// Linked instead of the Vulkan device listing when the project is configured with
// NEUFLOW_VULKAN=OFF.
#include "neuflow/model/gpu_devices.hpp"

namespace neuflow::model {

std::vector<GpuDevice> list_gpu_devices() {
  throw BackendError(BackendError::Kind::unavailable,
                     "this build of neuflow has no Vulkan backend (configured with -DNEUFLOW_VULKAN=OFF)");
}

std::size_t vulkan_validation_message_count() { return 0; }

}  // namespace neuflow::model
