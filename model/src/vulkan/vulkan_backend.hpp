#pragma once
// The Vulkan backend as FlowSession sees it: a device with the model's weights on it, opened
// once per session, and a plan per model size. Builds without Vulkan (NEUFLOW_VULKAN=OFF)
// link vulkan_unavailable.cpp instead, whose every call throws BackendError(unavailable).
#include <memory>
#include <string>

#include "inference_backend.hpp"

namespace neuflow::model {

struct VulkanContext;

// index -1: the first discrete or integrated GPU, else the first device. fp16 on a device
// without it opens fp32 and says so in `note`. Throws BackendError.
std::shared_ptr<VulkanContext> open_vulkan(const std::shared_ptr<const FlowModel>& model, int index,
                                           Precision precision, std::string& note);
// "vulkan device 0 (NVIDIA H200)", with ", fp16" when it stores fp16 and ", tensor cores" (or
// ", tensor cores emulated") when its products run there (product_kernels.hpp).
std::string describe(const VulkanContext& context);
// How many streamed frames a Vulkan backend keeps in flight (its staging ring).
inline constexpr int kVulkanStreamDepth = 2;
// Throws BackendError (out of memory, ...).
std::unique_ptr<InferenceBackend> make_vulkan_backend(const std::shared_ptr<VulkanContext>& context, int height,
                                                      int width);
// For backend=auto: the index of the device to use (the given one, or the first discrete or
// integrated GPU), or -1 when there is none (also without Vulkan at all).
int find_gpu_for_auto(int requested);

}  // namespace neuflow::model
