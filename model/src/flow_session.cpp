#include "neuflow/model/flow_session.hpp"

#include <omp.h>

#include <algorithm>
#include <deque>
#include <exception>
#include <stdexcept>
#include <string>
#include <utility>

#include "backend_registry.hpp"
#include "frame_geometry.hpp"
#include "inference_backend.hpp"
#include "memory_limit.hpp"

namespace neuflow::model {

// Slots of the backend: the stream alternates between two (the previous frame's and the
// current one's); compute() uses the two that do not hold the stream's previous frame.
struct FlowSession::State {
  FrameGeometry geometry;
  std::unique_ptr<BackendRegistry> backends;  // where the network runs, and its fallback
  const NetworkWeights* weights = nullptr;    // the model's, for the memory a plan needs
  std::unique_ptr<InferenceBackend> backend;  // the plan for the current model size
  Tensor input;                               // a frame converted here, for a backend that does not convert it itself
  int previous_slot = 0;
  bool has_previous = false;
  StageObserver observer;
  std::vector<StageTime> stage_times;  // of the last compute(), push() or take()
  DeviceWork work;                     // the same call's
  // Frames submitted and not taken, oldest first: on the backend still (started there), or
  // finished with their result kept.
  struct InFlight {
    bool started = false;
    std::optional<flow::FlowField> result;
    FrameGeometry geometry;
    std::exception_ptr failure;  // finished early and failed: take() throws it
  };
  std::deque<InFlight> in_flight;
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
  state_->backends = std::make_unique<BackendRegistry>(model_, options_);
  state_->weights = &model_->weights();
}

FlowSession::~FlowSession() = default;

void FlowSession::set_observer(StageObserver observer) { state_->observer = std::move(observer); }

void FlowSession::reset() { state_->has_previous = false; }

int FlowSession::in_flight() const { return static_cast<int>(state_->in_flight.size()); }

int FlowSession::max_in_flight() const {
  // Before the first frame there is no backend yet: a session opened on a GPU pipelines
  // (unless backend=auto leaves it for the CPU at the first frame).
  const auto& s = *state_;
  if (s.backend) return std::max(1, s.backend->stream_depth());
  return s.backends->stream_depth();
}

std::optional<std::string> FlowSession::memory_problem(int frame_width, int frame_height) const {
  FrameGeometry g;
  try {
    g = plan_geometry(frame_width, frame_height, options_);
  } catch (const std::invalid_argument&) {
    return std::nullopt;  // a size the session refuses anyway, with its own reason
  }
  return model::memory_problem(*state_->weights, options_, g.model_height, g.model_width);
}

std::optional<std::string> FlowSession::frame_problem(int frame_width, int frame_height) const {
  FrameGeometry g;
  try {
    g = plan_geometry(frame_width, frame_height, options_);
  } catch (const std::invalid_argument& e) {
    return std::string(e.what());
  }
  return model::memory_problem(*state_->weights, options_, g.model_height, g.model_width);
}

const std::string& FlowSession::backend_description() const { return state_->backends->description(); }
const std::string& FlowSession::fallback_warning() const { return state_->backends->fallback(); }
const std::vector<StageTime>& FlowSession::device_stage_times() const { return state_->stage_times; }
const DeviceWork& FlowSession::device_work() const { return state_->work; }

namespace {

// OpenMP's thread count is per calling thread; oneDNN and our loops both read it. An earlier
// session on this thread may have changed it: 0 sets OpenMP's default back (as the process
// started with it) rather than keeping that.
void apply_threads(int threads) {
  static const int openmp_default = omp_get_max_threads();
  omp_set_num_threads(threads > 0 ? threads : openmp_default);
}

// The flow of a frame the backend has finished, at the frame's own size.
std::optional<flow::FlowField> finished_flow(FlowSession::State& s, const FrameGeometry& g) {
  const Tensor* flow = s.backend->finish();
  if (!flow) return std::nullopt;
  return restore_flow(*flow, g);
}

// Finishes the frames submitted and still on the backend, keeping their results, so the
// backend is idle after. One that fails keeps its failure for its own take(): every submit()
// still matches one take(), and the call that needed the backend idle goes on.
void finish_started(FlowSession::State& s) {
  for (auto& f : s.in_flight) {
    if (!f.started) continue;
    f.started = false;
    try {
      f.result = finished_flow(s, f.geometry);
    } catch (...) {
      f.failure = std::current_exception();
    }
  }
}

// Makes the state ready for frames of this size: a new size ends the stream, and a new
// model size replaces the plan (the old one's buffers are released first). With
// backend=auto, a GPU that cannot hold this size leaves the session on the CPU.
const FrameGeometry& prepare_plan(FlowSession::State& s, const SessionOptions& options, int width, int height) {
  const FrameGeometry g = plan_geometry(width, height, options);
  if (s.backend && g == s.geometry) return s.geometry;
  finish_started(s);  // their passes use the plan about to be replaced
  if (!s.backend || s.backend->width() != g.model_width || s.backend->height() != g.model_height) {
    if (auto problem = memory_problem(*s.weights, options, g.model_height, g.model_width)) {
      throw std::invalid_argument(*problem);
    }
    s.backend.reset();  // its buffers are released before the next plan's are made
    s.backend = s.backends->make(g.model_height, g.model_width);
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
  s.work = s.backend->take_device_work();
  if (s.observer) {
    s.stage_times.clear();
    s.work = {};
  }
}

// Forgets what a call that failed half-way left.
void drop_stage_times(FlowSession::State& s) {
  s.stage_times.clear();
  s.work = {};
  s.backend->take_stage_times();
  s.backend->take_device_work();
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
  finish_started(s);  // the backend computes pairs with nothing of the stream outstanding
  const FrameGeometry& g = prepare_plan(s, options_, frame0.width, frame0.height);
  drop_stage_times(s);
  const auto [first, second] = free_slots(s.previous_slot);
  check_image(frame0, g);
  check_image(frame1, g);
  encode(s, frame0, g, options_.network_order, first);
  encode(s, frame1, g, options_.network_order, second);
  const Tensor& model_flow = s.backend->flow(first, second, iterations, &s.observer);
  keep_stage_times(s);
  return restore_flow(model_flow, g);
}

namespace {

// The slot a stream's next frame goes to. A stream alternates between slots 0 and 1, so the
// third (what compute() takes while a stream is open) holds no features unless compute() is
// used: 48 MB at 1920×1088 on the CPU. A pipelined step may reuse the slot its predecessor
// still reads: the device runs them in order.
int next_stream_slot(const FlowSession::State& s) { return s.previous_slot == 0 ? 1 : 0; }

// One frame of a stream, computed now: push()'s work, without its check for frames in flight.
std::optional<flow::FlowField> stream_now(FlowSession::State& s, const SessionOptions& options, const ImageView& frame,
                                          const Iterations& iterations) {
  validate(iterations);
  apply_threads(options.threads);
  const FrameGeometry& g = prepare_plan(s, options, frame.width, frame.height);
  drop_stage_times(s);
  const int current = next_stream_slot(s);
  check_image(frame, g);
  encode(s, frame, g, options.network_order, current);
  std::optional<flow::FlowField> result;
  if (s.has_previous) {
    result = restore_flow(s.backend->flow(s.previous_slot, current, iterations, &s.observer), g);
  }
  keep_stage_times(s);
  s.previous_slot = current;
  s.has_previous = true;
  return result;
}

}  // namespace

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame) { return push(frame, options_.iterations); }

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame, const Iterations& iterations) {
  if (!state_->in_flight.empty()) {
    throw std::logic_error("FlowSession::push with submitted frames not yet taken: take() them first");
  }
  return stream_now(*state_, options_, frame, iterations);
}

void FlowSession::submit(const ImageView& frame) { submit(frame, options_.iterations); }

void FlowSession::submit(const ImageView& frame, const Iterations& iterations) {
  auto& s = *state_;
  if (in_flight() >= max_in_flight()) {
    throw std::logic_error("FlowSession::submit: " + std::to_string(in_flight()) +
                           " frames are waiting to be taken, the most in flight");
  }
  validate(iterations);
  apply_threads(options_.threads);
  const FrameGeometry& g = prepare_plan(s, options_, frame.width, frame.height);
  check_image(frame, g);
  if (s.backend->stream_depth() == 0 || s.observer) {
    // Computed now, once the frames before it are finished (their results keep their order).
    finish_started(s);
    s.in_flight.push_back({false, stream_now(s, options_, frame, iterations), g, nullptr});
    return;
  }
  s.backend->take_stage_times();
  const int current = next_stream_slot(s);
  s.backend->start({frame, g, options_.network_order, current, s.has_previous ? s.previous_slot : -1, iterations});
  s.in_flight.push_back({true, std::nullopt, g});
  s.previous_slot = current;
  s.has_previous = true;
}

std::optional<flow::FlowField> FlowSession::take() {
  auto& s = *state_;
  if (s.in_flight.empty()) throw std::logic_error("FlowSession::take: no frame submitted");
  State::InFlight f = std::move(s.in_flight.front());
  s.in_flight.pop_front();
  s.stage_times.clear();  // a frame finished early (for compute() or a new size) has none
  s.work = {};
  if (f.failure) std::rethrow_exception(f.failure);
  if (!f.started) return std::move(f.result);
  std::optional<flow::FlowField> result = finished_flow(s, f.geometry);
  keep_stage_times(s);
  return result;
}

}  // namespace neuflow::model
