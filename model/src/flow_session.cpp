#include "neuflow/model/flow_session.hpp"

#include <omp.h>

#include <stdexcept>
#include <utility>

#include "dnnl/context.hpp"
#include "frame_geometry.hpp"
#include "network.hpp"

namespace neuflow::model {

struct FlowSession::State {
  dnnl::stream stream{cpu_engine()};
  FrameGeometry geometry;
  std::unique_ptr<NetworkPlan> plan;
  Tensor input, model_flow;
  FrameFeatures previous, current;   // the stream
  FrameFeatures pair_first, pair_second;  // compute(), kept apart from the stream
  bool has_previous = false;
  StageObserver observer;
};

namespace {

void validate(const Iterations& it) {
  if (auto problem = check_iterations_s16(it.s16)) throw std::invalid_argument("iters-s16: " + *problem);
  if (auto problem = check_iterations_s8(it.s8)) throw std::invalid_argument("iters-s8: " + *problem);
}

}  // namespace

FlowSession::FlowSession(std::shared_ptr<const FlowModel> model, SessionOptions options)
    : options_(options), model_(std::move(model)), state_(std::make_unique<State>()) {
  if (!model_) throw std::invalid_argument("FlowSession needs a loaded model");
  if (auto problem = check_session_options(options_)) throw std::invalid_argument(*problem);
}

FlowSession::~FlowSession() = default;

void FlowSession::set_observer(StageObserver observer) { state_->observer = std::move(observer); }

void FlowSession::reset() { state_->has_previous = false; }

namespace {

// OpenMP's thread count is per calling thread; oneDNN and our loops both read it.
void apply_threads(int threads) {
  if (threads > 0) omp_set_num_threads(threads);
}

// Makes the state ready for frames of this size: a new size ends the stream, and a new
// model size replaces the plan (the old one's buffers are released first).
const FrameGeometry& prepare_plan(FlowSession::State& s, const NetworkWeights& weights, const SessionOptions& options,
                                  int width, int height) {
  const FrameGeometry g = plan_geometry(width, height, options);
  if (s.plan && g == s.geometry) return s.geometry;
  if (!s.plan || s.plan->width() != g.model_width || s.plan->height() != g.model_height) {
    s.plan.reset();
    s.plan = std::make_unique<NetworkPlan>(weights, g.model_height, g.model_width);
  }
  s.geometry = g;
  s.has_previous = false;
  return s.geometry;
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
  const FrameGeometry& g = prepare_plan(s, model_->weights(), options_, frame0.width, frame0.height);
  prepare_input(frame0, g, options_.network_order, s.input);
  s.plan->encode(s.stream, s.input, s.pair_first);
  prepare_input(frame1, g, options_.network_order, s.input);
  s.plan->encode(s.stream, s.input, s.pair_second);
  s.plan->flow(s.stream, s.pair_first, s.pair_second, iterations.s16, iterations.s8, s.model_flow, &s.observer);
  return restore_flow(s.model_flow, g);
}

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame) { return push(frame, options_.iterations); }

std::optional<flow::FlowField> FlowSession::push(const ImageView& frame, const Iterations& iterations) {
  validate(iterations);
  apply_threads(options_.threads);
  auto& s = *state_;
  const FrameGeometry& g = prepare_plan(s, model_->weights(), options_, frame.width, frame.height);
  prepare_input(frame, g, options_.network_order, s.input);
  s.plan->encode(s.stream, s.input, s.current);
  std::optional<flow::FlowField> result;
  if (s.has_previous) {
    s.plan->flow(s.stream, s.previous, s.current, iterations.s16, iterations.s8, s.model_flow, &s.observer);
    result = restore_flow(s.model_flow, g);
  }
  std::swap(s.previous, s.current);
  s.has_previous = true;
  return result;
}

}  // namespace neuflow::model
