#include "vulkan/vulkan_instance.hpp"

#include <array>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

namespace neuflow::model::vulkan {

namespace {

std::atomic<std::size_t> validation_messages{0};

// NEUFLOW_VULKAN_VALIDATION=sync: synchronization validation as well (slower).
bool synchronization_validation_requested() {
  const char* v = std::getenv("NEUFLOW_VULKAN_VALIDATION");
  return v != nullptr && std::strcmp(v, "sync") == 0;
}

bool validation_requested() {
  const char* v = std::getenv("NEUFLOW_VULKAN_VALIDATION");
  return v != nullptr && *v != '\0' && std::strcmp(v, "0") != 0;
}

VKAPI_ATTR VkBool32 VKAPI_CALL on_validation_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                     VkDebugUtilsMessageTypeFlagsEXT,
                                                     const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  const bool error = (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) != 0;
  ++validation_messages;
  std::fprintf(stderr, "neuflow: Vulkan validation %s: %s\n", error ? "error" : "warning",
               data && data->pMessage ? data->pMessage : "(no text)");
  const char* mode = std::getenv("NEUFLOW_VULKAN_VALIDATION");
  if (mode != nullptr && std::strcmp(mode, "fatal") == 0) std::abort();
  return VK_FALSE;
}

struct Instance {
  VkInstance handle = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
};

bool layer_available(const char* name) {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const auto& l : layers) {
    if (std::strcmp(l.layerName, name) == 0) return true;
  }
  return false;
}

Instance create_instance() {
  if (volkInitialize() != VK_SUCCESS) {
    throw BackendError(BackendError::Kind::unavailable,
                       "Vulkan is not available: the Vulkan loader (libvulkan.so.1) was not found; install it "
                       "(Debian/Ubuntu: libvulkan1, plus a driver such as mesa-vulkan-drivers or the GPU vendor's)");
  }
  if (volkGetInstanceVersion() < VK_API_VERSION_1_1) {
    throw BackendError(BackendError::Kind::unavailable, "Vulkan is not available: the loader is older than Vulkan 1.1");
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "neuflow";
  app.pEngineName = "neuflow";
  // 1.2 where the loader has it: the fp16 features are core there.
  app.apiVersion = volkGetInstanceVersion() >= VK_API_VERSION_1_2 ? VK_API_VERSION_1_2 : VK_API_VERSION_1_1;
  VkInstanceCreateInfo info{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  info.pApplicationInfo = &app;
  const char* layer = "VK_LAYER_KHRONOS_validation";
  const std::array<const char*, 2> extensions{VK_EXT_DEBUG_UTILS_EXTENSION_NAME,
                                              VK_EXT_VALIDATION_FEATURES_EXTENSION_NAME};
  const VkValidationFeatureEnableEXT enabled = VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT;
  VkValidationFeaturesEXT features{VK_STRUCTURE_TYPE_VALIDATION_FEATURES_EXT};
  features.enabledValidationFeatureCount = 1;
  features.pEnabledValidationFeatures = &enabled;
  const bool validate = validation_requested();
  if (validate) {
    if (!layer_available(layer)) {
      throw BackendError(BackendError::Kind::unavailable,
                         "NEUFLOW_VULKAN_VALIDATION is set but the Khronos validation layer is not installed "
                         "(Debian: vulkan-validationlayers)");
    }
    info.enabledLayerCount = 1;
    info.ppEnabledLayerNames = &layer;
    info.enabledExtensionCount = static_cast<uint32_t>(extensions.size());
    info.ppEnabledExtensionNames = extensions.data();
    // Synchronization validation too: the recorder leaves out the barriers between commands
    // that do not depend on each other, and this is what reports one it left out wrongly.
    if (synchronization_validation_requested()) info.pNext = &features;
  }
  Instance inst;
  const VkResult r = vkCreateInstance(&info, nullptr, &inst.handle);
  if (r != VK_SUCCESS) {
    throw BackendError(BackendError::Kind::unavailable,
                       "Vulkan is not available: vkCreateInstance failed: " + result_text(r));
  }
  volkLoadInstance(inst.handle);
  if (validate) {
    VkDebugUtilsMessengerCreateInfoEXT m{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                    VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
    m.pfnUserCallback = on_validation_message;
    check(vkCreateDebugUtilsMessengerEXT(inst.handle, &m, nullptr, &inst.messenger), "Vulkan",
          "vkCreateDebugUtilsMessengerEXT");
  }
  return inst;
}

std::string version_text(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

}  // namespace

VkInstance instance() {
  // Created once; a failure is remembered so every later caller gets the same message.
  static std::mutex mutex;
  static Instance created;
  static std::string failure;
  const std::lock_guard lock(mutex);
  if (created.handle != VK_NULL_HANDLE) return created.handle;
  if (!failure.empty()) throw BackendError(BackendError::Kind::unavailable, failure);
  try {
    created = create_instance();
  } catch (const BackendError& e) {
    failure = e.what();
    throw;
  }
  return created.handle;
}

std::vector<VkPhysicalDevice> physical_devices() {
  VkInstance inst = instance();
  uint32_t count = 0;
  check(vkEnumeratePhysicalDevices(inst, &count, nullptr), "Vulkan", "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> devices(count);
  check(vkEnumeratePhysicalDevices(inst, &count, devices.data()), "Vulkan", "vkEnumeratePhysicalDevices");
  devices.resize(count);
  return devices;
}

namespace {

bool has_extension(VkPhysicalDevice device, const char* name) {
  uint32_t count = 0;
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> extensions(count);
  vkEnumerateDeviceExtensionProperties(device, nullptr, &count, extensions.data());
  for (const auto& e : extensions) {
    if (std::strcmp(e.extensionName, name) == 0) return true;
  }
  return false;
}

// What the *_coopmat shaders (matmul_fragments.comp with TENSOR_CORES) need: the extension and
// its feature, the memory model its scopes are written in, a 16×16×16 fp16 × fp16 + fp32 shape
// at subgroup scope, and subgroups of 32 (a workgroup of 128 is 4 of them, 2×2 fragments each).
bool has_tensor_cores(VkPhysicalDevice device, bool vulkan12) {
  if (!vulkan12 || !has_extension(device, VK_NV_COOPERATIVE_MATRIX_EXTENSION_NAME) ||
      vkGetPhysicalDeviceCooperativeMatrixPropertiesNV == nullptr) {
    return false;
  }
  VkPhysicalDeviceCooperativeMatrixFeaturesNV matrices{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_COOPERATIVE_MATRIX_FEATURES_NV};
  VkPhysicalDeviceVulkanMemoryModelFeatures memory_model{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_MEMORY_MODEL_FEATURES};
  memory_model.pNext = &matrices;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &memory_model;
  vkGetPhysicalDeviceFeatures2(device, &features);
  if (!matrices.cooperativeMatrix || !memory_model.vulkanMemoryModel) return false;

  VkPhysicalDeviceSubgroupProperties subgroup{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
  VkPhysicalDeviceProperties2 props{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props.pNext = &subgroup;
  vkGetPhysicalDeviceProperties2(device, &props);
  if (subgroup.subgroupSize != 32) return false;

  uint32_t count = 0;
  if (vkGetPhysicalDeviceCooperativeMatrixPropertiesNV(device, &count, nullptr) != VK_SUCCESS) return false;
  std::vector<VkCooperativeMatrixPropertiesNV> shapes(count, {VK_STRUCTURE_TYPE_COOPERATIVE_MATRIX_PROPERTIES_NV});
  if (vkGetPhysicalDeviceCooperativeMatrixPropertiesNV(device, &count, shapes.data()) != VK_SUCCESS) return false;
  for (const auto& s : shapes) {
    if (s.MSize == 16 && s.NSize == 16 && s.KSize == 16 && s.AType == VK_COMPONENT_TYPE_FLOAT16_NV &&
        s.BType == VK_COMPONENT_TYPE_FLOAT16_NV && s.CType == VK_COMPONENT_TYPE_FLOAT32_NV &&
        s.DType == VK_COMPONENT_TYPE_FLOAT32_NV && s.scope == VK_SCOPE_SUBGROUP_NV) {
      return true;
    }
  }
  return false;
}

}  // namespace

GpuDevice describe(VkPhysicalDevice device, int index) {
  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(device, &props);
  VkPhysicalDeviceMemoryProperties memory;
  vkGetPhysicalDeviceMemoryProperties(device, &memory);
  // shaderFloat16 is core in Vulkan 1.2; on older devices (and loaders) fp16 is not offered.
  VkPhysicalDeviceShaderFloat16Int8Features f16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_FLOAT16_INT8_FEATURES};
  VkPhysicalDevice16BitStorageFeatures storage16{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_16BIT_STORAGE_FEATURES};
  const bool vulkan12 = props.apiVersion >= VK_API_VERSION_1_2 && volkGetInstanceVersion() >= VK_API_VERSION_1_2;
  if (vulkan12) storage16.pNext = &f16;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &storage16;
  vkGetPhysicalDeviceFeatures2(device, &features);

  GpuDevice d;
  d.index = index;
  d.name = props.deviceName;
  switch (props.deviceType) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: d.type = "discrete"; break;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: d.type = "integrated"; break;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: d.type = "virtual"; break;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: d.type = "cpu"; break;
    default: d.type = "other"; break;
  }
  d.api_version = version_text(props.apiVersion);
  d.driver = "driver version " + std::to_string(props.driverVersion);
  for (uint32_t h = 0; h < memory.memoryHeapCount; ++h) {
    if (memory.memoryHeaps[h].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT) d.memory_bytes += memory.memoryHeaps[h].size;
  }
  d.max_buffer_bytes = props.limits.maxStorageBufferRange;
  d.fp16 = vulkan12 && f16.shaderFloat16 && storage16.storageBuffer16BitAccess;
  d.tensor_cores = d.fp16 && has_tensor_cores(device, vulkan12);
  // The queue family VulkanDevice takes: the first with compute.
  uint32_t families = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(device, &families, nullptr);
  std::vector<VkQueueFamilyProperties> family(families);
  vkGetPhysicalDeviceQueueFamilyProperties(device, &families, family.data());
  for (const auto& f : family) {
    if (f.queueFlags & VK_QUEUE_COMPUTE_BIT) {
      d.timestamps = f.timestampValidBits > 0 && props.limits.timestampPeriod > 0;
      break;
    }
  }
  return d;
}

}  // namespace neuflow::model::vulkan

namespace neuflow::model {

std::vector<GpuDevice> list_gpu_devices() {
  const auto devices = vulkan::physical_devices();
  std::vector<GpuDevice> out;
  for (std::size_t i = 0; i < devices.size(); ++i) out.push_back(vulkan::describe(devices[i], static_cast<int>(i)));
  return out;
}

std::size_t vulkan_validation_message_count() { return vulkan::validation_messages.load(); }

}  // namespace neuflow::model
