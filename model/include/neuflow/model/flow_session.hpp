#pragma once
// Computing flow with a loaded model: for a pair of images, or frame by frame on a stream,
// where each frame's backbone features are computed once and reused for the next pair.
// A session is used by one thread at a time; several sessions may share one FlowModel.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "neuflow/flow/flow_field.hpp"
#include "neuflow/model/device_work.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "neuflow/model/image_view.hpp"
#include "neuflow/model/session_settings.hpp"
#include "neuflow/model/stage_observer.hpp"

namespace neuflow::model {

class FlowSession {
 public:
  // Opens the backend the options ask for. Throws std::invalid_argument for unusable options
  // and BackendError (gpu_devices.hpp) when backend=vulkan cannot open its device; with
  // backend=auto a GPU that fails is left for the CPU (see fallback_warning()).
  explicit FlowSession(std::shared_ptr<const FlowModel> model, SessionOptions options = {});
  ~FlowSession();
  FlowSession(const FlowSession&) = delete;
  FlowSession& operator=(const FlowSession&) = delete;

  // Throws std::invalid_argument with check_session_options()'s message for unusable options.
  // Flow from frame0 to frame1 at frame0's size (both must have the same size). Does not
  // touch the stream state. Throws std::invalid_argument for unusable images.
  flow::FlowField compute(const ImageView& frame0, const ImageView& frame1);
  flow::FlowField compute(const ImageView& frame0, const ImageView& frame1, const Iterations& iterations);

  // Streaming: the flow from the previous frame to this one, or nothing for the first frame
  // (and the first after reset() or a change of frame size).
  std::optional<flow::FlowField> push(const ImageView& frame);
  std::optional<flow::FlowField> push(const ImageView& frame, const Iterations& iterations);
  void reset();

  // Pipelined streaming, for a caller that has the next frame before it needs the last flow:
  // submit() does what push() does, but on a backend that overlaps frames (Vulkan: the frame
  // goes up through a staging ring while the pair before it computes) it returns before the
  // flow is computed; take() waits for the oldest submitted frame and returns what push() would
  // have returned for it. At most max_in_flight() frames are submitted and not taken (1 on the
  // CPU, where submit() computes); submit() beyond that, and push() with frames in flight,
  // throw std::logic_error. compute(), reset() and a change of frame size keep the frames in
  // flight (finished first where needed). A frame whose computation fails (a lost device)
  // throws from its own take(), also when it was finished early: each submit() has one take().
  void submit(const ImageView& frame);
  void submit(const ImageView& frame, const Iterations& iterations);
  std::optional<flow::FlowField> take();
  int in_flight() const;
  int max_in_flight() const;

  // Sees every intermediate of subsequent passes (for reference comparisons).
  void set_observer(StageObserver observer);

  const SessionOptions& options() const { return options_; }

  // Why frames of this size would need more memory than max-memory allows (the size, the need
  // and the limit), or nothing; push() and compute() refuse such frames with this message. A
  // GStreamer element asks at negotiation, before any frame.
  std::optional<std::string> memory_problem(int frame_width, int frame_height) const;
  // Why push() and compute() would refuse frames of this size: a size the network cannot take
  // (as their std::invalid_argument says it), or memory_problem(); nothing when they can. The
  // command-line tools ask with an image's header before decoding it.
  std::optional<std::string> frame_problem(int frame_width, int frame_height) const;

  // Where the network runs: "cpu" or "vulkan device 0 (NVIDIA H200)".
  const std::string& backend_description() const;
  // What the session does other than asked, once: backend=auto leaving a GPU it found for the
  // CPU, or fp16 on a device without it running fp32. Empty otherwise. Callers report it once.
  const std::string& fallback_warning() const;

  // Where the last compute(), push() or take() spent its time on a GPU, measured by the device's own
  // timestamps (not the host's clock, so without submission and read-back): each stage in the
  // order it ran, the frames' encodings first. Empty on the CPU backend (time its stages with
  // an observer), while an observer is set, and on a device whose queue has no timestamps.
  const std::vector<StageTime>& device_stage_times() const;
  // What the same call asked of the GPU: its commands, barriers, submissions and host waits,
  // with each command's bytes and multiply-adds from its shapes (device_work.hpp). Empty where
  // device_stage_times() is, except that a queue without timestamps still counts.
  const DeviceWork& device_work() const;

  struct State;  // opaque per-session buffers and stream state

 private:
  SessionOptions options_;
  std::shared_ptr<const FlowModel> model_;
  std::unique_ptr<State> state_;
};

}  // namespace neuflow::model
