#include "vulkan/vulkan_device.hpp"

#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "vulkan/vulkan_instance.hpp"

namespace neuflow::model::vulkan {

Buffer& Buffer::operator=(Buffer&& other) noexcept {
  if (this != &other) {
    if (device_) device_->release(*this);
    device_ = std::move(other.device_);
    buffer_ = std::exchange(other.buffer_, VK_NULL_HANDLE);
    memory_ = std::exchange(other.memory_, VK_NULL_HANDLE);
    bytes_ = std::exchange(other.bytes_, 0);
    mapped_ = std::exchange(other.mapped_, nullptr);
    counted_ = std::exchange(other.counted_, false);
  }
  return *this;
}

Buffer::~Buffer() {
  if (device_) device_->release(*this);
}

namespace {

std::size_t budget_from_environment() {
  const char* v = std::getenv("NEUFLOW_VULKAN_MEMORY_BUDGET_MB");
  if (v == nullptr || *v == '\0') return 0;
  char* end = nullptr;
  const unsigned long long mb = std::strtoull(v, &end, 10);
  return (end && *end == '\0') ? static_cast<std::size_t>(mb) << 20 : 0;
}

// NEUFLOW_VULKAN_LOSE_DEVICE_AFTER=N: each device opened while it is set reports itself lost at
// its (N+1)th submission, as a driver does after a GPU hang or reset; nothing else can lose a
// device on purpose, and the recovery (the error, a new session on a new device, neuflowd's
// restart of that stream) needs testing. -1 when unset.
long long lose_after_from_environment() {
  const char* v = std::getenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER");
  if (v == nullptr || *v == '\0') return -1;
  char* end = nullptr;
  const long long n = std::strtoll(v, &end, 10);
  return (end && *end == '\0' && n >= 0) ? n : -1;
}

int pick_default(const std::vector<VkPhysicalDevice>& devices) {
  for (std::size_t i = 0; i < devices.size(); ++i) {
    if (describe(devices[i], static_cast<int>(i)).is_gpu()) return static_cast<int>(i);
  }
  return 0;
}

}  // namespace

std::shared_ptr<VulkanDevice> VulkanDevice::open(int index) {
  static std::mutex mutex;
  static std::map<int, std::weak_ptr<VulkanDevice>> opened;
  const auto devices = physical_devices();
  if (devices.empty()) {
    throw BackendError(BackendError::Kind::unavailable,
                       "no Vulkan device: the loader found no driver with a device (install the GPU's Vulkan "
                       "driver; `neuflow devices` lists what Vulkan sees)");
  }
  if (index < 0) index = pick_default(devices);
  if (index >= static_cast<int>(devices.size())) {
    throw BackendError(BackendError::Kind::unavailable, "no Vulkan device " + std::to_string(index) +
                                                            ": this machine has " + std::to_string(devices.size()) +
                                                            " (0 to " + std::to_string(devices.size() - 1) +
                                                            "; `neuflow devices` lists them)");
  }
  // What the shaders need: Vulkan 1.1 SPIR-V, workgroups of 256 invocations (16×16 tiles), and
  // up to 32 KiB of shared memory: the fused Winograd convolutions take 27 KiB (scalar) and
  // 30 KiB (on fragments), the products on fragments 28.5 KiB in 128×128 tiles. Every GPU this
  // targets has at least that (Jetson and NVIDIA 48 KiB, AMD and Intel 64 KiB, lavapipe 32 KiB).
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(devices[static_cast<std::size_t>(index)], &props);
  const std::string label = "vulkan device " + std::to_string(index) + " (" + props.deviceName + ")";
  if (props.apiVersion < VK_API_VERSION_1_1) {
    throw BackendError(BackendError::Kind::unavailable, label + ": supports only Vulkan 1.0; the shaders need 1.1");
  }
  if (props.limits.maxComputeWorkGroupInvocations < 256 || props.limits.maxComputeWorkGroupSize[0] < 256 ||
      props.limits.maxComputeWorkGroupSize[1] < 16 || props.limits.maxComputeSharedMemorySize < 32768) {
    throw BackendError(BackendError::Kind::unavailable,
                       label + ": compute workgroups are too small for the shaders (they need 256 invocations and " +
                           "32 KiB of shared memory; it has " +
                           std::to_string(props.limits.maxComputeSharedMemorySize / 1024) + " KiB)");
  }
  if (props.limits.maxPerStageDescriptorStorageBuffers < kShaderBindings) {
    throw BackendError(BackendError::Kind::unavailable,
                       label + ": a shader may bind only " +
                           std::to_string(props.limits.maxPerStageDescriptorStorageBuffers) +
                           " storage buffers; the shaders need " + std::to_string(kShaderBindings));
  }
  const std::lock_guard lock(mutex);
  if (auto device = opened[index].lock(); device && !device->lost_) return device;
  auto device = std::shared_ptr<VulkanDevice>(new VulkanDevice(devices[static_cast<std::size_t>(index)], index));
  opened[index] = device;
  return device;
}

VulkanDevice::VulkanDevice(VkPhysicalDevice physical, int index)
    : physical_(physical),
      info_(describe(physical, index)),
      budget_(budget_from_environment()),
      lose_after_(lose_after_from_environment()) {
  label_ = "vulkan device " + std::to_string(index) + " (" + info_.name + ")";
  vkGetPhysicalDeviceMemoryProperties(physical_, &memory_);

  uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, nullptr);
  std::vector<VkQueueFamilyProperties> family(families);
  vkGetPhysicalDeviceQueueFamilyProperties(physical_, &families, family.data());
  bool found = false;
  for (uint32_t f = 0; f < families && !found; ++f) {
    if (family[f].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      queue_family_ = f;
      timestamp_bits_ = family[f].timestampValidBits;
      found = true;
    }
  }
  if (!found) throw BackendError(BackendError::Kind::unavailable, label_ + ": has no compute queue");
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(physical_, &props);
  timestamp_period_ns_ = props.limits.timestampPeriod;
  if (timestamp_period_ns_ <= 0) timestamp_bits_ = 0;

  const float priority = 1.f;
  VkDeviceQueueCreateInfo queue{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  queue.queueFamilyIndex = queue_family_;
  queue.queueCount = 1;
  queue.pQueuePriorities = &priority;
  VkDeviceCreateInfo info{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  VkPhysicalDeviceShaderFloat16Int8Features f16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES};
  VkPhysicalDevice16BitStorageFeatures storage16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES};
  VkPhysicalDeviceCooperativeMatrixFeaturesNV matrices{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_COOPERATIVE_MATRIX_FEATURES_NV};
  VkPhysicalDeviceVulkanMemoryModelFeatures memory_model{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_MEMORY_MODEL_FEATURES};
  const char* const cooperative_matrix = VK_NV_COOPERATIVE_MATRIX_EXTENSION_NAME;
  if (info_.fp16) {  // the fp16 shader variants need both
    f16.shaderFloat16 = VK_TRUE;
    storage16.storageBuffer16BitAccess = VK_TRUE;
    storage16.pNext = &f16;
    info.pNext = &storage16;
  }
  if (info_.tensor_cores) {  // the *_coopmat shaders (describe() checked all of it)
    matrices.cooperativeMatrix = VK_TRUE;
    memory_model.vulkanMemoryModel = VK_TRUE;
    memory_model.pNext = &matrices;
    f16.pNext = &memory_model;
    info.enabledExtensionCount = 1;
    info.ppEnabledExtensionNames = &cooperative_matrix;
  }
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  check(vkCreateDevice(physical_, &info, nullptr, &device_), "vkCreateDevice");
  vkGetDeviceQueue(device_, queue_family_, 0, &queue_);
  try {
    create_pipelines();
  } catch (...) {
    destroy();
    throw;
  }
}

void VulkanDevice::create_pipelines() {
  std::array<VkDescriptorSetLayoutBinding, kBindings> bindings{};
  for (int b = 0; b < kBindings; ++b) {
    bindings[b].binding = static_cast<uint32_t>(b);
    bindings[b].descriptorType = VK_DESCRIPTOR_TYPE_STORAGE_BUFFER;
    bindings[b].descriptorCount = 1;
    bindings[b].stageFlags = VK_SHADER_STAGE_COMPUTE_BIT;
  }
  VkDescriptorSetLayoutCreateInfo set{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set.bindingCount = kBindings;
  set.pBindings = bindings.data();
  check(vkCreateDescriptorSetLayout(device_, &set, nullptr, &set_layout_), "vkCreateDescriptorSetLayout");
  VkPushConstantRange push{VK_SHADER_STAGE_COMPUTE_BIT, 0, kPushConstantBytes};
  VkPipelineLayoutCreateInfo layout{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout.setLayoutCount = 1;
  layout.pSetLayouts = &set_layout_;
  layout.pushConstantRangeCount = 1;
  layout.pPushConstantRanges = &push;
  check(vkCreatePipelineLayout(device_, &layout, nullptr, &pipeline_layout_), "vkCreatePipelineLayout");

  // Every fp32 pipeline this device can run now, so pipeline() reads them without a lock; the
  // fp16 ones on first use.
  for (std::size_t s = 0; s < kShaderCount; ++s) {
    if (can_run(static_cast<Shader>(s), false)) pipelines_[s] = create_pipeline(static_cast<Shader>(s), false);
  }
}

bool VulkanDevice::can_run(Shader shader, bool fp16) const {
  const ShaderInfo& s = shader_info(shader);
  return (fp16 ? info_.fp16 : !s.spirv.empty()) && (!s.tensor_cores || info_.tensor_cores);
}

VkPipeline VulkanDevice::create_pipeline(Shader shader, bool fp16, const GemmTile* tile) {
  const auto code = spirv(shader, fp16);
  std::string name = std::string(shader_name(shader)) + (fp16 ? " (fp16)" : "");
  if (tile) name += ", " + std::to_string(tile->rows()) + "x" + std::to_string(tile->columns()) + " tiles";
  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = code.size_bytes();
  module_info.pCode = code.data();
  VkShaderModule module = VK_NULL_HANDLE;
  check(vkCreateShaderModule(device_, &module_info, nullptr, &module), "vkCreateShaderModule(" + name + ")");
  VkComputePipelineCreateInfo pipeline{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pipeline.stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
  pipeline.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeline.stage.module = module;
  pipeline.stage.pName = "main";
  // The products' constant_id 0 and 1 (TM and TN), and the fragments' workgroup size as the
  // code reads it (2) and as the workgroup has it (3); matmul.comp has neither, and ignores them.
  const int32_t invocations = tile ? tile->fragment_invocations() : 0;
  const std::array<int32_t, 4> tile_values{tile ? tile->tm : 0, tile ? tile->tn : 0, invocations, invocations};
  std::array<VkSpecializationMapEntry, 4> entries{};
  for (uint32_t i = 0; i < entries.size(); ++i) entries[i] = {i, i * uint32_t{sizeof(int32_t)}, sizeof(int32_t)};
  const VkSpecializationInfo specialization{static_cast<uint32_t>(entries.size()), entries.data(), sizeof tile_values,
                                            tile_values.data()};
  if (tile) pipeline.stage.pSpecializationInfo = &specialization;
  pipeline.layout = pipeline_layout_;
  VkPipeline created = VK_NULL_HANDLE;
  const VkResult r = vkCreateComputePipelines(device_, VK_NULL_HANDLE, 1, &pipeline, nullptr, &created);
  vkDestroyShaderModule(device_, module, nullptr);
  if (r != VK_SUCCESS) {
    throw BackendError(BackendError::Kind::driver,
                       label_ + ": the driver rejected the compute pipeline '" + name + "': " + result_text(r));
  }
  return created;
}

VkPipeline VulkanDevice::pipeline(Shader shader, bool fp16) {
  const auto s = static_cast<std::size_t>(shader);
  if (!can_run(shader, fp16)) {
    throw BackendError(BackendError::Kind::unavailable, label_ + ": cannot run the shader '" + shader_name(shader) +
                                                            "' in " + (fp16 ? "fp16" : "fp32") +
                                                            " (it needs fp16 or tensor cores this device lacks)");
  }
  if (!fp16) return pipelines_[s];
  const std::lock_guard lock(pipeline_mutex_);
  if (fp16_pipelines_[s] == VK_NULL_HANDLE) fp16_pipelines_[s] = create_pipeline(shader, true);
  return fp16_pipelines_[s];
}

VkPipeline VulkanDevice::pipeline(Shader shader, bool fp16, GemmTile tile) {
  if (tile == kGemmTile64) return pipeline(shader, fp16);
  if (!can_run(shader, fp16)) return pipeline(shader, fp16);  // throws, saying why
  const std::lock_guard lock(pipeline_mutex_);
  VkPipeline& p = tiled_pipelines_[{shader, fp16, tile.tm, tile.tn}];
  if (p == VK_NULL_HANDLE) p = create_pipeline(shader, fp16, &tile);
  return p;
}

VulkanDevice::~VulkanDevice() { destroy(); }

void VulkanDevice::destroy() {
  if (device_ == VK_NULL_HANDLE) return;
  vkDeviceWaitIdle(device_);
  for (auto* set : {&pipelines_, &fp16_pipelines_}) {
    for (VkPipeline& p : *set) {
      if (p != VK_NULL_HANDLE) vkDestroyPipeline(device_, p, nullptr);
      p = VK_NULL_HANDLE;
    }
  }
  for (auto& [key, p] : tiled_pipelines_) {
    if (p != VK_NULL_HANDLE) vkDestroyPipeline(device_, p, nullptr);
  }
  tiled_pipelines_.clear();
  if (pipeline_layout_ != VK_NULL_HANDLE) vkDestroyPipelineLayout(device_, pipeline_layout_, nullptr);
  if (set_layout_ != VK_NULL_HANDLE) vkDestroyDescriptorSetLayout(device_, set_layout_, nullptr);
  pipeline_layout_ = VK_NULL_HANDLE;
  set_layout_ = VK_NULL_HANDLE;
  vkDestroyDevice(device_, nullptr);
  device_ = VK_NULL_HANDLE;
}

void VulkanDevice::check(VkResult result, std::string_view call) const {
  if (result == VK_SUCCESS) return;
  vulkan::check(result, label_, call);
}

uint32_t VulkanDevice::memory_type(uint32_t allowed, Memory memory) const {
  // Uploads and read-backs alike: memory the host maps, coherent.
  const VkMemoryPropertyFlags want = memory == Memory::device
                                         ? VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT
                                         : VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  // Read-backs prefer cached memory (reads from write-combined memory are slow).
  const VkMemoryPropertyFlags prefer = memory == Memory::readback ? VK_MEMORY_PROPERTY_HOST_CACHED_BIT : 0;
  for (int pass = 0; pass < 2; ++pass) {
    for (uint32_t t = 0; t < memory_.memoryTypeCount; ++t) {
      const VkMemoryPropertyFlags flags = memory_.memoryTypes[t].propertyFlags;
      if (!(allowed & (1u << t)) || (flags & want) != want) continue;
      if (pass == 0 && (flags & prefer) != prefer) continue;
      return t;
    }
  }
  throw BackendError(BackendError::Kind::driver, label_ + ": no memory type for a buffer");
}

Buffer VulkanDevice::create_buffer(std::size_t bytes, Memory memory, const std::string& what) {
  bytes = (std::max<std::size_t>(bytes, 16) + 15) / 16 * 16;  // whole 32-bit words for every view of it
  if (bytes > info_.max_buffer_bytes) {
    throw BackendError(BackendError::Kind::out_of_memory,
                       label_ + ": " + what + " needs " + std::to_string(bytes >> 20) +
                           " MiB in one buffer, more than the device's maxStorageBufferRange (" +
                           std::to_string(info_.max_buffer_bytes >> 20) + " MiB): use a smaller model size");
  }
  // The budget is on device memory; staging buffers are the host's.
  const bool counted = memory == Memory::device;
  if (counted) {
    const std::lock_guard lock(memory_mutex_);
    if (budget_ != 0 && allocated_ + bytes > budget_) {
      throw BackendError(BackendError::Kind::out_of_memory,
                         label_ + ": out of device memory allocating " + std::to_string((bytes + (1 << 20) - 1) >> 20) +
                             " MiB for " + what + " (NEUFLOW_VULKAN_MEMORY_BUDGET_MB allows " +
                             std::to_string(budget_ >> 20) + " MiB, " + std::to_string(allocated_ >> 20) +
                             " MiB in use)");
    }
    allocated_ += bytes;
  }
  Buffer b;
  b.device_ = shared_from_this();
  b.bytes_ = bytes;
  b.counted_ = counted;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  const auto fail = [&](VkResult r, const char* call) {
    if (r == VK_SUCCESS) return;
    throw BackendError(
        r == VK_ERROR_OUT_OF_DEVICE_MEMORY || r == VK_ERROR_OUT_OF_HOST_MEMORY ? BackendError::Kind::out_of_memory
                                                                               : BackendError::Kind::driver,
        label_ + ": " + call + " failed for " + what + " (" + std::to_string(bytes >> 20) + " MiB): " + result_text(r));
  };
  fail(vkCreateBuffer(device_, &info, nullptr, &b.buffer_), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(device_, b.buffer_, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(req.memoryTypeBits, memory);
  fail(vkAllocateMemory(device_, &alloc, nullptr, &b.memory_), "vkAllocateMemory");
  fail(vkBindBufferMemory(device_, b.buffer_, b.memory_, 0), "vkBindBufferMemory");
  if (memory != Memory::device) fail(vkMapMemory(device_, b.memory_, 0, VK_WHOLE_SIZE, 0, &b.mapped_), "vkMapMemory");
  return b;
}

void VulkanDevice::release(Buffer& b) {
  if (b.mapped_) vkUnmapMemory(device_, b.memory_);
  if (b.buffer_ != VK_NULL_HANDLE) vkDestroyBuffer(device_, b.buffer_, nullptr);
  if (b.memory_ != VK_NULL_HANDLE) vkFreeMemory(device_, b.memory_, nullptr);
  if (b.counted_) {
    const std::lock_guard lock(memory_mutex_);
    allocated_ -= std::min(allocated_, b.bytes_);
  }
  b.buffer_ = VK_NULL_HANDLE;
  b.memory_ = VK_NULL_HANDLE;
  b.mapped_ = nullptr;
  b.bytes_ = 0;
  b.device_.reset();  // last: may destroy this device
}

void VulkanDevice::submit_and_wait(VkCommandBuffer commands, VkFence fence) {
  submit(commands, fence);
  wait(fence);
}

void VulkanDevice::submit(VkCommandBuffer commands, VkFence fence) {
  if (lost_) {
    throw BackendError(BackendError::Kind::device_lost, label_ + ": the device was lost earlier; start a new session");
  }
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 1;
  submit.pCommandBuffers = &commands;
  VkResult r;
  {
    // Sessions on one device share its queue, which Vulkan requires to be used by one thread
    // at a time; waits happen outside the lock so their work overlaps on the device.
    const std::lock_guard lock(queue_mutex_);
    const bool lose_now = lose_after_ >= 0 && submissions_++ >= lose_after_;
    r = lose_now ? VK_ERROR_DEVICE_LOST : vkQueueSubmit(queue_, 1, &submit, fence);
  }
  if (r == VK_ERROR_DEVICE_LOST) lost_ = true;
  check(r, "running the network (vkQueueSubmit)");
}

void VulkanDevice::wait(VkFence fence) {
  VkResult r = vkWaitForFences(device_, 1, &fence, VK_TRUE, UINT64_MAX);
  if (r == VK_SUCCESS) r = vkResetFences(device_, 1, &fence);
  // Work that was in flight when the device was lost (at a later submission, or as
  // NEUFLOW_VULKAN_LOSE_DEVICE_AFTER makes it) has no result to trust either.
  if (r == VK_SUCCESS && lost_) r = VK_ERROR_DEVICE_LOST;
  if (r == VK_ERROR_DEVICE_LOST) lost_ = true;
  check(r, "running the network (vkWaitForFences)");
}

}  // namespace neuflow::model::vulkan
