#include <array>

#include "dnnl/context.hpp"
#include "inference_backend.hpp"
#include "network.hpp"

namespace neuflow::model {

namespace {

// Today's oneDNN network behind the backend interface; the frames' features stay in host memory.
class CpuBackend final : public InferenceBackend {
 public:
  CpuBackend(const NetworkWeights& weights, int height, int width, CpuConvolution convolution)
      : plan_(weights, height, width, convolution) {}
  int width() const override { return plan_.width(); }
  int height() const override { return plan_.height(); }
  void encode(const Tensor& image, int slot) override {
    plan_.encode(stream_, image, slots_[static_cast<std::size_t>(slot)]);
  }
  // Converted into the plan's arena rather than a tensor of the session's (25 MB at 1920×1088).
  bool encode_frame(const ImageView& image, const FrameGeometry& geometry, ChannelOrder network_order,
                    int slot) override {
    prepare_input(image, geometry, network_order, plan_.input());
    encode(plan_.input(), slot);
    return true;
  }
  const Tensor& flow(int slot0, int slot1, const Iterations& iterations, const StageObserver* observer) override {
    return plan_.flow(stream_, slots_[static_cast<std::size_t>(slot0)], slots_[static_cast<std::size_t>(slot1)],
                      iterations.s16, iterations.s8, observer);
  }

 private:
  dnnl::stream stream_{cpu_engine()};
  NetworkPlan plan_;
  std::array<FrameFeatures, kSlots> slots_;
};

}  // namespace

CpuConvolution resolve_cpu_convolution(CpuConvolution requested) {
  if (requested != CpuConvolution::automatic) return requested;
  return cpu_convolution_from_environment().value_or(requested);
}

std::unique_ptr<InferenceBackend> make_cpu_backend(const FlowModel& model, int height, int width,
                                                   CpuConvolution convolution) {
  return std::make_unique<CpuBackend>(model.weights(), height, width, resolve_cpu_convolution(convolution));
}

}  // namespace neuflow::model
