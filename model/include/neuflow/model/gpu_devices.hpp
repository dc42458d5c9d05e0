#pragma once
// The GPUs a session can run on (Vulkan compute), and the error every GPU failure becomes.
#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace neuflow::model {

// A GPU backend failure, with a message naming the device and the cause.
class BackendError : public std::runtime_error {
 public:
  enum class Kind {
    unavailable,    // no Vulkan loader, no driver, or no such device
    out_of_memory,  // device (or host) memory exhausted, or the configured budget
    device_lost,    // the device was lost; a new session opens it again
    driver,         // the driver refused something else (e.g. a pipeline)
  };
  BackendError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const { return kind_; }

 private:
  Kind kind_;
};

struct GpuDevice {
  int index = 0;                       // what SessionOptions::device, --device and `device =` take
  std::string name;                    // e.g. "NVIDIA H200", "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string type;                    // discrete, integrated, virtual, cpu, other
  std::string api_version;             // e.g. "1.3.230"
  std::string driver;                  // driver name and version text
  std::uint64_t memory_bytes = 0;      // device-local heaps
  std::uint64_t max_buffer_bytes = 0;  // maxStorageBufferRange
  bool fp16 = false;                   // shaderFloat16 and 16-bit storage
  // VK_NV_cooperative_matrix with 16×16×16 fp16 × fp16 + fp32 products in subgroups of 32 (and
  // the Vulkan memory model): fp16 sessions run their products on tensor cores.
  bool tensor_cores = false;
  bool timestamps = false;  // its compute queue has timestamps: FlowSession::device_stage_times()
  bool is_gpu() const { return type == "discrete" || type == "integrated"; }
};

// Every Vulkan device, in the driver's order. Throws BackendError (unavailable) when the
// Vulkan loader or a driver is missing; an empty list means a loader without devices.
std::vector<GpuDevice> list_gpu_devices();

// With NEUFLOW_VULKAN_VALIDATION=1 the Khronos validation layer checks every call; this counts
// the warnings and errors it reported in this process (each is also printed on stderr).
std::size_t vulkan_validation_message_count();

}  // namespace neuflow::model
