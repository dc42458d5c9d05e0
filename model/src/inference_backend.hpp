#pragma once
// The narrow interface FlowSession runs the network through, one implementation per backend
// (cpu/: oneDNN; vulkan/: compute shaders). A backend holds a plan for one model size and
// keeps the features of up to kSlots encoded frames, so the session can stream (each frame
// encoded once, serving two pairs) and compute pairs without disturbing the stream.
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

#include "frame_geometry.hpp"
#include "neuflow/model/device_work.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/model/stage_observer.hpp"
#include "tensor.hpp"

namespace neuflow::model {

class InferenceBackend {
 public:
  static constexpr int kSlots = 3;

  virtual ~InferenceBackend() = default;

  virtual int width() const = 0;
  virtual int height() const = 0;

  // image: [height, width, 3] in 0..1, in the network's channel order.
  virtual void encode(const Tensor& image, int slot) = 0;
  // The frame from its 8-bit pixels, converted by the backend itself (as prepare_input() would:
  // the image is checked already). False where the backend leaves that to the session, which
  // then converts on the CPU and calls encode().
  virtual bool encode_frame(const ImageView& /*image*/, const FrameGeometry& /*geometry*/,
                            ChannelOrder /*network_order*/, int /*slot*/) {
    return false;
  }
  // Flow from the frame in slot0 to the frame in slot1: [height, width, 2] (u, v), in the
  // backend's own memory until its next call. The observer, when set, sees every named stage
  // (the same names on every backend).
  virtual const Tensor& flow(int slot0, int slot1, const Iterations& iterations, const StageObserver* observer) = 0;
  // The device's own time for each stage of the passes since the last call, where the backend
  // measures one (the GPU's timestamps); the CPU's stages are timed with an observer instead.
  virtual std::vector<StageTime> take_stage_times() { return {}; }
  // What the device was asked to do since the last call, where the backend counts it (a GPU's).
  virtual DeviceWork take_device_work() { return {}; }

  // Pipelined streaming (FlowSession::submit): a backend that overlaps frames starts a step
  // (the frame's encoding into `slot` and, unless previous is -1, its pair) without waiting,
  // and finishes the steps in order. stream_depth(): how many may be unfinished; 0 where the
  // backend does not pipeline (the session then streams through encode() and flow()).
  struct StreamStep {
    ImageView frame;
    FrameGeometry geometry;
    ChannelOrder network_order;
    int slot = 0, previous = -1;
    Iterations iterations;
  };
  virtual int stream_depth() const { return 0; }
  virtual void start(const StreamStep& /*step*/) {
    throw std::logic_error("InferenceBackend::start on a backend that does not pipeline");
  }
  // The oldest started step's flow, valid until the backend's next call; nullptr without a pair.
  virtual const Tensor* finish() {
    throw std::logic_error("InferenceBackend::finish on a backend that does not pipeline");
  }
};

// `convolution` automatic defers to NEUFLOW_CONV (auto, direct, winograd, winograd4 or
// winograd6) when it is set.
std::unique_ptr<InferenceBackend> make_cpu_backend(const FlowModel& model, int height, int width,
                                                   CpuConvolution convolution);
// The choice a session's plan is built with: `requested`, or for automatic, NEUFLOW_CONV's
// value when set; std::invalid_argument naming the variable when that value is none of them.
CpuConvolution resolve_cpu_convolution(CpuConvolution requested);

}  // namespace neuflow::model
