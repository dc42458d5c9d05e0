#pragma once
// Where a session's network runs, decided in one place: which device the options name, and the
// fallback policy of backend=auto (a GPU that cannot be opened, or cannot hold a model size,
// leaves the session on the CPU with a warning; backend=vulkan fails instead). FlowSession asks
// it for a backend per model size and knows no backend by name.
#include <memory>
#include <string>

#include "inference_backend.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::model {

struct VulkanContext;

class BackendRegistry {
 public:
  // Opens the device the options ask for. Throws BackendError where backend=vulkan cannot.
  BackendRegistry(std::shared_ptr<const FlowModel> model, const SessionOptions& options);
  ~BackendRegistry();
  BackendRegistry(const BackendRegistry&) = delete;
  BackendRegistry& operator=(const BackendRegistry&) = delete;

  // A plan for this model size on the chosen device; with backend=auto, the CPU's when the
  // device cannot hold it (from then on, fallback() says why). Throws BackendError otherwise.
  std::unique_ptr<InferenceBackend> make(int height, int width);

  // "cpu", or "vulkan device N (name)[, fp16]".
  const std::string& description() const { return description_; }
  // Why backend=auto runs on the CPU, or a device's note (fp16 unavailable); empty when none.
  const std::string& fallback() const { return fallback_; }
  // Frames a stream may keep in flight on the chosen device, before a plan exists.
  int stream_depth() const;

 private:
  void leave_for_cpu(const std::string& why);

  std::shared_ptr<const FlowModel> model_;
  SessionOptions options_;
  std::shared_ptr<VulkanContext> vulkan_;  // set while the chosen device is a Vulkan one
  std::string description_ = "cpu";
  std::string fallback_;
};

}  // namespace neuflow::model
