#pragma once
// One opened Vulkan device: its compute queue, memory, and the compute pipelines of every
// shader, created once and shared by all sessions on that device (open() hands out the same
// instance while anyone holds it).
#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <tuple>
#include <utility>

#include "vulkan/gemm_tile.hpp"
#include "vulkan/shaders.hpp"
#include "vulkan/vulkan_api.hpp"

namespace neuflow::model::vulkan {

class VulkanDevice;

// A storage buffer with its own memory: device-local for tensors, host-visible (mapped) for
// uploads and read-backs. Move-only; released with the device kept alive by it.
class Buffer {
 public:
  Buffer() = default;
  Buffer(Buffer&& other) noexcept { *this = std::move(other); }
  Buffer& operator=(Buffer&& other) noexcept;
  ~Buffer();

  VkBuffer handle() const { return buffer_; }
  std::size_t bytes() const { return bytes_; }
  float* mapped() const { return static_cast<float*>(mapped_); }

 private:
  friend class VulkanDevice;
  std::shared_ptr<VulkanDevice> device_;
  VkBuffer buffer_ = VK_NULL_HANDLE;
  VkDeviceMemory memory_ = VK_NULL_HANDLE;
  std::size_t bytes_ = 0;
  void* mapped_ = nullptr;
  bool counted_ = false;  // against the device memory budget
};

class VulkanDevice : public std::enable_shared_from_this<VulkanDevice> {
 public:
  // index: a device of list_gpu_devices(); -1: the first discrete or integrated GPU, else the
  // first device. Throws BackendError naming the device and the cause.
  static std::shared_ptr<VulkanDevice> open(int index);

  ~VulkanDevice();
  VulkanDevice(const VulkanDevice&) = delete;
  VulkanDevice& operator=(const VulkanDevice&) = delete;

  const GpuDevice& info() const { return info_; }
  // "vulkan device 0 (NVIDIA H200)": how errors and logs name it.
  const std::string& label() const { return label_; }
  VkDevice handle() const { return device_; }
  uint32_t queue_family() const { return queue_family_; }
  // Timestamp queries on the compute queue: the counter's valid bits (0: none) and the
  // nanoseconds per tick.
  uint32_t timestamp_bits() const { return timestamp_bits_; }
  double timestamp_period_ns() const { return timestamp_period_ns_; }
  // The fp16 variants are created on first use. Throws BackendError for a shader the device
  // cannot run (can_run()).
  VkPipeline pipeline(Shader shader, bool fp16);
  // A product's pipeline (matmul.comp, matmul_fragments.comp) specialized to `tile`; the 64×64
  // tile is the shaders' own, the others are created on first use.
  VkPipeline pipeline(Shader shader, bool fp16, GemmTile tile);
  // Whether the shader exists in that precision and the device has what it needs.
  bool can_run(Shader shader, bool fp16) const;
  VkPipelineLayout pipeline_layout() const { return pipeline_layout_; }
  VkDescriptorSetLayout set_layout() const { return set_layout_; }

  enum class Memory { device, upload, readback };
  // `what` names the buffer in an out-of-memory error. Device memory is held within
  // NEUFLOW_VULKAN_MEMORY_BUDGET_MB when that is set (to share a GPU, or to test running out).
  Buffer create_buffer(std::size_t bytes, Memory memory, const std::string& what);

  // Submits and waits on `fence` (the caller's, unsignalled; left unsignalled). Throws
  // BackendError (device lost, ...) naming the device. After a lost device every later call
  // fails and open() creates a new device. NEUFLOW_VULKAN_LOSE_DEVICE_AFTER=N, when a device is
  // opened, makes it report itself lost at its (N+1)th submission (to test that path).
  void submit_and_wait(VkCommandBuffer commands, VkFence fence);
  // The two halves of submit_and_wait(), for work the host overlaps with its own: submit()
  // signals `fence` when done; wait() waits for it and leaves it unsignalled again.
  void submit(VkCommandBuffer commands, VkFence fence);
  void wait(VkFence fence);

  // Throws if `where` failed, naming this device.
  void check(VkResult result, std::string_view call) const;

  // Every binding of every shader is one of these storage buffers.
  static constexpr int kBindings = static_cast<int>(kShaderBindings);
  static constexpr std::size_t kPushConstantBytes = 128;

 private:
  friend class Buffer;
  VulkanDevice(VkPhysicalDevice physical, int index);
  void create_pipelines();
  VkPipeline create_pipeline(Shader shader, bool fp16, const GemmTile* tile = nullptr);
  void destroy();
  uint32_t memory_type(uint32_t allowed, Memory memory) const;
  void release(Buffer& buffer);

  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  GpuDevice info_;
  std::string label_;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t queue_family_ = 0;
  uint32_t timestamp_bits_ = 0;
  double timestamp_period_ns_ = 0;
  VkPhysicalDeviceMemoryProperties memory_{};
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout_ = VK_NULL_HANDLE;
  std::array<VkPipeline, kShaderCount> pipelines_{};
  std::array<VkPipeline, kShaderCount> fp16_pipelines_{};
  // The products' other tiles: (shader, fp16, TM, TN).
  std::map<std::tuple<Shader, bool, int, int>, VkPipeline> tiled_pipelines_;
  std::mutex pipeline_mutex_;
  std::mutex queue_mutex_;
  std::mutex memory_mutex_;
  std::size_t allocated_ = 0;
  std::size_t budget_ = 0;     // 0: no budget
  long long lose_after_ = -1;  // NEUFLOW_VULKAN_LOSE_DEVICE_AFTER; -1: never
  long long submissions_ = 0;  // guarded by queue_mutex_
  std::atomic<bool> lost_{false};
};

}  // namespace neuflow::model::vulkan
