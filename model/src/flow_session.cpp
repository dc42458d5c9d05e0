#include "neuflow/model/flow_session.hpp"

#include <omp.h>

#include <stdexcept>
#include <utility>

#include "frame_geometry.hpp"
#include "inference_backend.hpp"
#include "vulkan/vulkan_backend.hpp"

namespace neuflow::model {

// Slots of the backend: the stream alternates between two (the previous frame's and the
// current one's); compute() uses the two that do not hold the stream's previous frame.
struct FlowSession::State {
  FrameGeometry geometry;
  std::unique_ptr<InferenceBackend> backend;
  std::shared_ptr<VulkanContext> vulkan;  // set while the session runs on a Vulkan device
  std::string description = "cpu";
  std::string fallback;
  Tensor input;  // a frame converted here, for a backend that does not convert it itself
  int previous_slot = 0;
  bool has_previous = false;
  StageObserver observer;
  std::vector<StageTime> stage_times;  // of the last compute() or push()
};

namespace {

void validate(const Iterations& it) {
  if (auto problem = check_iterations_s16(it.s16)) throw std::invalid_argument("iters-s16: " + *problem);
  if (auto problem = check_iterations_s8(it.s8)) throw std::invalid_argument("iters-s8: " + *problem);
}

// The two slots other than `taken`.
std::pair<int, int> free_slots(int taken) {
  const int a = (taken + 1) % InferenceBackend::kSlots, b = (taken + 2) % InferenceBackend::kSlots;
  return {a, b};
}

}  // namespace

FlowSession::FlowSession(std::shared_ptr<const FlowModel> model, SessionOptions options)
    : options_(options), model_(std::move(model)), state_(std::make_unique<State>()) {
  if (!model_) throw std::invalid_argument("FlowSession needs a loaded model");
  if (auto problem = check_session_options(options_)) throw std::invalid_argument(*problem);
  cpu_convolution_from_environment();  // a bad NEUFLOW_CONV fails here, before any frame
  auto& s = *state_;
  if (options_.backend == Backend::vulkan) {
    s.vulkan = open_vulkan(model_, options_.device, options_.precision, s.fallback);
  } else if (options_.backend == Backend::automatic) {
    if (const int gpu = find_gpu_for_auto(options_.device); gpu >= 0) {
      try {
        s.vulkan = open_vulkan(model_, gpu, options_.precision, s.fallback);
      } catch (const BackendError& e) {
        s.fallback = std::string("backend auto: ") + e.what() + "; running on the CPU instead";
      }
    } else if (options_.device >= 0) {
      s.fallback = "backend auto: no Vulkan device " + std::to_string(options_.device) +
                   " (`neuflow devices` lists them); running on the CPU instead";
    }
  }
  if (s.vulkan) s.description = describe(*s.vulkan);
}

FlowSession::~FlowSession() = default;

void FlowSession::set_observer(StageObserver observer) { state_->observer = std::move(observer); }

void FlowSession::reset() { state_->has_previous = false; }

const std::string& FlowSession::backend_description() const { return state_->description; }
const std::string& FlowSession::fallback_warning() const { return state_->fallback; }
const std::vector<StageTime>& FlowSession::device_stage_times() const { return state_->stage_times; }

namespace {

// OpenMP's thread count is per calling thread; oneDNN and our loops both read it.
void apply_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

// Makes the state ready for frames of this size: a new size ends the stream, and a new
// model size replaces the plan (the old one's buffers are released first). With
// backend=auto, a GPU that cannot hold this size leaves the session on the CPU.
const FrameGeometry& prepare_plan(FlowSession::State& s, const FlowModel& model, const SessionOptions& options,
                                  int width, int height) {
  const FrameGeometry g = plan_geometry(width, height, options);
  if (s.backend && g == s.geometry) return s.geometry;
  if (!s.backend || s.backend->width() != g.model_width || s.backend->height() != g.model_height) {
    s.backend.reset();
    if (s.vulkan) {
      try {
        s.backend = make_vulkan_backend(s.vulkan, g.model_height, g.model_width);
      } catch (const BackendError& e) {
        if (options.backend != Backend::automatic) throw;
        s.fallback = std::string("backend auto: ") + e.what() + "; running on the CPU instead";
        s.vulkan.reset();
        s.description = "cpu";
      }
    }
    if (!s.backend) s.backend = make_cpu_backend(model, g.model_height, g.model_width, options.cpu_convolution);
  }
  s.geometry = g;
  s.has_previous = false;
  return s.geometry;
}

// The backend converts the frame itself where it can (a GPU: from the 8-bit pixels, a quarter
// of the bytes to upload), else it is converted here.
void encode(FlowSession::State& s, const ImageView& frame, const FrameGeometry& g, ChannelOrder order, int slot) {
  if (s.backend->encode_frame(frame, g, order, slot)) return;
  prepare_input(frame, g, order, s.input);
  s.backend->encode(s.input, slot);
}

// A call with an observer reads every stage back, so its times are not the network's.
void keep_stage_times(FlowSession::State& s) {
  s.stage_times = s.backend->take_stage_times();
  if (s.observer) s.stage_times.clear();
}

}  // namespace

flow::FlowField FlowSession::compute(const ImageView& frame0, const ImageView& frame1) {
  return compute(frame0, frame1, options_.iterations);
}

flow::FlowField FlowSession::compute(const ImageView& frame0, const ImageView& frame1, const Iterations& iterations) {
  validate(iterations);
  if (frame0.width != frame1.width || frame0.height != frame1.height) {
    throw std::invalid_argument("the two frames differ in size");
  }
  apply_threads(options_.threads);
  auto& s = *state_;
  const FrameGeometry& g = prepare_plan(s, *model_, options_, frame0.width, frame0.height);
  s.stage_times.clear();
  s.backend->take_stage_times();  // what a call that failed half-way left
  const auto [first, second] = free_slots(s.previous_slot);
  check_image(frame0, g);
  check_image(frame1, g);
  encode(s, frame0, g, options_.network_order, first);
  encode(s, frame1, g, options_.network_order, second);
  const Tensor& model_flow = s.backend->flow(first, second, iterations, &s.observer);
  keep_stage_times(s);
  return restore_flow(model_flow, g);
}

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame) { return push(frame, options_.iterations); }

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame, const Iterations& iterations) {
  validate(iterations);
  apply_threads(options_.threads);
  auto& s = *state_;
  const FrameGeometry& g = prepare_plan(s, *model_, options_, frame.width, frame.height);
  s.stage_times.clear();
  s.backend->take_stage_times();
  // A stream alternates between slots 0 and 1, so the third (what compute() takes while a
  // stream is open) holds no features unless compute() is used: 48 MB at 1920×1088 on the CPU.
  const int current = s.previous_slot == 0 ? 1 : 0;
  check_image(frame, g);
  encode(s, frame, g, options_.network_order, current);
  std::optional<flow::FlowField> result;
  if (s.has_previous) {
    result = restore_flow(s.backend->flow(s.previous_slot, current, iterations, &s.observer), g);
  }
  keep_stage_times(s);
  s.previous_slot = current;
  s.has_previous = true;
  return result;
}

}  // namespace neuflow::model
