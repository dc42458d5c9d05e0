#include "vulkan/vulkan_backend.hpp"

#include <thread>

#include "vulkan/conv_algorithm.hpp"
#include "vulkan/device_weights.hpp"
#include "vulkan/gemm_tile.hpp"
#include "vulkan/product_kernels.hpp"
#include "vulkan/vulkan_instance.hpp"
#include "vulkan/vulkan_network.hpp"

namespace neuflow::model {

struct VulkanContext {
  std::shared_ptr<const vulkan::DeviceWeights> weights;
  vulkan::ProductKernels products = vulkan::ProductKernels::scalar;
  vulkan::ConvAlgorithm conv = vulkan::ConvAlgorithm::winograd_fused;
  vulkan::GemmTiles gemm_tiles;
};

namespace {

class VulkanBackend final : public InferenceBackend {
 public:
  VulkanBackend(std::shared_ptr<VulkanContext> context, int height, int width)
      : context_(std::move(context)),
        network_(context_->weights, height, width, context_->products, context_->conv, context_->gemm_tiles) {}
  int width() const override { return network_.width(); }
  int height() const override { return network_.height(); }
  void encode(const Tensor& image, int slot) override { network_.encode(image, slot); }
  // Padding mode on the device; a resize (OpenCV's fixed-point bilinear) stays on the CPU.
  bool encode_frame(const ImageView& image, const FrameGeometry& g, ChannelOrder network_order, int slot) override {
    if (g.resize) return false;
    network_.encode(device_frame(image, g, network_order), slot);
    return true;
  }
  const Tensor& flow(int slot0, int slot1, const Iterations& iterations, const StageObserver* observer) override {
    network_.flow(slot0, slot1, iterations, flow_, observer);
    return flow_;
  }
  std::vector<StageTime> take_stage_times() override { return network_.take_stage_times(); }
  DeviceWork take_device_work() override { return network_.take_device_work(); }

  static_assert(kVulkanStreamDepth == vulkan::VulkanNetwork::kRing);
  int stream_depth() const override { return vulkan::VulkanNetwork::kRing; }
  void start(const StreamStep& step) override {
    vulkan::VulkanNetwork::Step s;
    s.slot = step.slot;
    s.previous = step.previous;
    s.iterations = step.iterations;
    const vulkan::VulkanNetwork::Frame frame = device_frame(step.frame, step.geometry, step.network_order);
    if (step.geometry.resize) {  // as in encode_frame(): the resize stays on the CPU
      prepare_input(step.frame, step.geometry, step.network_order, converted_);
      s.image = &converted_;
    } else {
      s.frame = &frame;
    }
    network_.start(s);
  }
  const Tensor* finish() override { return network_.finish(flow_) ? &flow_ : nullptr; }

 private:
  // The 8-bit frame as the device converts it in padding mode.
  static vulkan::VulkanNetwork::Frame device_frame(const ImageView& image, const FrameGeometry& g,
                                                   ChannelOrder network_order) {
    return {image.data, image.stride, {image.width, image.height, g.pad_left, g.pad_top, image.order != network_order}};
  }

  std::shared_ptr<VulkanContext> context_;
  vulkan::VulkanNetwork network_;
  Tensor flow_;       // the last pair's, read back from the device
  Tensor converted_;  // a resized frame, converted here before its upload
};

}  // namespace

std::shared_ptr<VulkanContext> open_vulkan(const std::shared_ptr<const FlowModel>& model, int index,
                                           Precision precision, std::string& note) {
  auto device = vulkan::VulkanDevice::open(index);
  bool fp16 = precision == Precision::fp16;
  if (fp16 && !device->info().fp16) {
    note = "precision fp16: " + device->label() +
           " has no shaderFloat16 and 16-bit storage (Vulkan 1.2); running in fp32 instead";
    fp16 = false;
  }
  auto context = std::make_shared<VulkanContext>();
  context->products = vulkan::product_kernels_for(device->info(), fp16);
  if (fp16) {  // those it records created now, so a driver that refuses one says so before the first frame
    for (std::size_t s = 0; s < vulkan::kShaderCount; ++s) {
      const auto shader = static_cast<vulkan::Shader>(s);
      if (vulkan::records(shader, context->products)) device->pipeline(shader, true);
    }
  }
  context->conv = vulkan::conv_algorithm_for();
  context->gemm_tiles = vulkan::gemm_tiles_for(device->info().is_gpu(), std::thread::hardware_concurrency());
  context->weights = vulkan::DeviceWeights::get(model, device, fp16,
                                                vulkan::winograd_filters_at_upload(context->conv, context->products));
  return context;
}

std::string describe(const VulkanContext& context) {
  std::string text = context.weights->device->label() + (context.weights->fp16 ? ", fp16" : "");
  if (context.products == vulkan::ProductKernels::tensor_cores) text += ", tensor cores";
  if (context.products == vulkan::ProductKernels::twin) text += ", tensor cores emulated";
  return text;
}

std::unique_ptr<InferenceBackend> make_vulkan_backend(const std::shared_ptr<VulkanContext>& context, int height,
                                                      int width) {
  return std::make_unique<VulkanBackend>(context, height, width);
}

int find_gpu_for_auto(int requested) {
  try {
    const auto devices = list_gpu_devices();
    if (requested >= 0) return requested < static_cast<int>(devices.size()) ? requested : -1;
    for (const auto& d : devices) {
      if (d.is_gpu()) return d.index;
    }
  } catch (const BackendError&) {
  }
  return -1;
}

}  // namespace neuflow::model
