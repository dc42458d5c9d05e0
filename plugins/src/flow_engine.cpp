#include "flow_engine.hpp"

#include <algorithm>
#include <mutex>
#include <utility>

#include "flow_meta_attach.hpp"

// The element's own category ("neuflow"), so that its log lines read as they always have.
GST_DEBUG_CATEGORY_STATIC(flow_engine_debug);
#define GST_CAT_DEFAULT flow_engine_debug

namespace neuflow::gst {

namespace {
constexpr std::size_t kEveryPairQueuedBuffers = 2;
// Results waiting for the push task: one is enough to overlap a push with the next inference.
constexpr std::size_t kResultsWaiting = 1;

void init_debug_category() {
  static std::once_flag once;
  std::call_once(once,
                 [] { GST_DEBUG_CATEGORY_INIT(flow_engine_debug, "neuflow", 0, "NeuFlow-V2 optical flow element"); });
}
}  // namespace

FlowEngine::FlowEngine(GstElement* element, Downstream& downstream, SettingsSource settings)
    : element_(element),
      downstream_(downstream),
      settings_(std::move(settings)),
      input_(kEveryPairQueuedBuffers),
      output_(kResultsWaiting) {
  init_debug_category();
  gst_segment_init(&segment_, GST_FORMAT_TIME);
  flush_handoffs();  // flushing until started
  g_rec_mutex_init(&inference_lock_);
  g_rec_mutex_init(&push_lock_);
  inference_ = gst_task_new(inference_loop, this, nullptr);
  gst_task_set_lock(inference_, &inference_lock_);
  push_ = gst_task_new(push_loop, this, nullptr);
  gst_task_set_lock(push_, &push_lock_);
}

FlowEngine::~FlowEngine() {
  stop();
  gst_object_unref(inference_);
  gst_object_unref(push_);
  g_rec_mutex_clear(&inference_lock_);
  g_rec_mutex_clear(&push_lock_);
}

void FlowEngine::release(Item& item) {
  if (item.buffer) gst_buffer_unref(item.buffer);
  if (item.event) gst_event_unref(item.event);
  item = {};
}

void FlowEngine::release_all(std::vector<Item> items) {
  for (auto& item : items) release(item);
}

// Both hand-offs refuse new items and wake their waiters; what was waiting is released.
void FlowEngine::flush_handoffs() {
  release_all(input_.start_flushing());
  release_all(output_.start_flushing());
}

// Pauses a task and waits until it has: a started task holds its lock until it pauses, and the
// loops pause themselves at the next flush they see.
void FlowEngine::pause_task(GstTask* task, GRecMutex& lock) {
  gst_task_pause(task);
  g_rec_mutex_lock(&lock);
  g_rec_mutex_unlock(&lock);
}

// ---- lifecycle -----------------------------------------------------------------------------

void FlowEngine::open(std::shared_ptr<const model::FlowModel> model, const model::SessionOptions& options) {
  session_ = std::make_unique<model::FlowSession>(std::move(model), options);
  reported_fallback_ = session_->fallback_warning();
  GST_INFO_OBJECT(element_, "running on %s", session_->backend_description().c_str());
  const std::lock_guard lock(lock_);
  running_on_ = session_->backend_description();
  stats_.restart(std::chrono::steady_clock::now());
  next_frame_ = 0;
  live_.reset();
  have_info_ = false;
  previous_pts_ = GST_CLOCK_TIME_NONE;
  gst_segment_init(&segment_, GST_FORMAT_TIME);
}

void FlowEngine::close() {
  if (session_) discard_in_flight();
  session_.reset();
  have_info_ = false;
}

std::string FlowEngine::running_on() const {
  const std::lock_guard lock(lock_);
  return running_on_;
}

std::string FlowEngine::fallback_warning() const { return reported_fallback_; }

// ---- the tasks -----------------------------------------------------------------------------

bool FlowEngine::start() {
  const std::lock_guard tasks(tasks_lock_);
  input_.stop_flushing();
  output_.stop_flushing();
  if (gst_task_start(inference_) && gst_task_start(push_)) {
    active_ = true;
    return true;
  }
  stop_tasks();
  return false;
}

void FlowEngine::stop() {
  const std::lock_guard tasks(tasks_lock_);
  stop_tasks();
  if (session_) discard_in_flight();  // both tasks have stopped: the worker's state is ours
}

void FlowEngine::stop_tasks() {
  active_ = false;
  flush_handoffs();
  // A started task holds its lock until it pauses; the loops pause themselves once they see the
  // flush. Stopped under the lock, a task cannot pause itself again after the stop, which would
  // leave the join waiting.
  for (auto [task, lock] : {std::pair{push_, &push_lock_}, std::pair{inference_, &inference_lock_}}) {
    g_rec_mutex_lock(lock);
    gst_task_stop(task);
    g_rec_mutex_unlock(lock);
    gst_task_join(task);
  }
}

// ---- the streaming thread ------------------------------------------------------------------

GstFlowReturn FlowEngine::chain(GstBuffer* buffer, const std::function<bool()>& upstream_is_live) {
  std::optional<bool> live;
  {
    const std::lock_guard lock(lock_);
    live = live_;
  }
  if (!live) {
    const model::Behaviour b = settings_().behaviour;
    const bool resolved = b == model::Behaviour::automatic ? upstream_is_live() : b == model::Behaviour::live;
    GST_INFO_OBJECT(element_, "behaviour: %s", resolved ? "live" : "every-pair");
    const std::lock_guard lock(lock_);
    live_ = live = resolved;
  }

  // Newest wins when live: a frame still waiting for the worker is replaced by this one (the
  // hand-off never waits then, so it happens under the counters' lock and they never show a
  // frame in that is neither waiting, computed nor dropped); its QoS message is posted after.
  // Every pair: wait for room, outside the lock.
  Item item{buffer, nullptr, 0};
  std::vector<Item> dropped;
  Handoff::Result queued = Handoff::Result::queued;
  guint64 processed = 0, drops = 0;
  GstSegment segment{};
  if (*live) {
    const std::lock_guard lock(lock_);
    stats_.frame_in();
    item.frame = next_frame_++;
    queued = input_.push_frame(item, Handoff::Policy::newest_wins, &dropped);
    stats_.dropped(dropped.size());
    processed = stats_.processed();
    drops = stats_.frames_dropped();
    segment = segment_;
  } else {
    {
      const std::lock_guard lock(lock_);
      stats_.frame_in();
      item.frame = next_frame_++;
    }
    queued = input_.push_frame(item, Handoff::Policy::back_pressure);
  }
  for (Item& old : dropped) {
    post_drop(old.buffer, segment, processed, drops);
    release(old);
  }
  if (queued == Handoff::Result::queued) return GST_FLOW_OK;
  gst_buffer_unref(buffer);
  return queued == Handoff::Result::flushing ? GST_FLOW_FLUSHING : static_cast<GstFlowReturn>(input_.failure());
}

bool FlowEngine::queue_event(GstEvent* event) {
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_CAPS: {
      GstCaps* caps = nullptr;
      gst_event_parse_caps(event, &caps);
      GstVideoInfo info;
      if (!gst_video_info_from_caps(&info, caps)) {
        gst_event_unref(event);
        return false;
      }
      break;  // applied by the worker in stream order
    }
    case GST_EVENT_SEGMENT: {
      const GstSegment* segment = nullptr;
      gst_event_parse_segment(event, &segment);
      const std::lock_guard lock(lock_);
      gst_segment_copy_into(segment, &segment_);
      break;
    }
    case GST_EVENT_STREAM_START: {
      const std::lock_guard lock(lock_);
      live_.reset();  // a new stream may come from a source of another kind
      break;
    }
    default: break;
  }
  Item item{nullptr, event, 0};
  if (input_.push_other(item) != Handoff::Result::queued) {
    gst_event_unref(event);
    return false;
  }
  return true;
}

void FlowEngine::begin_flush() { flush_handoffs(); }

void FlowEngine::pause_for_flush() {
  const std::lock_guard tasks(tasks_lock_);
  if (!active_) return;
  pause_task(push_, push_lock_);            // returns once the push task finished its current item
  pause_task(inference_, inference_lock_);  // returns once the worker finished its current item
}

bool FlowEngine::end_flush(const std::function<bool()>& forward) {
  const std::lock_guard tasks(tasks_lock_);
  if (!active_) return forward();  // being stopped: stays flushing
  // Paused again (idempotent): a FLUSH_STOP may come without its FLUSH_START, and a worker that
  // saw the flush must not pause itself after the restart below.
  flush_handoffs();
  pause_task(push_, push_lock_);
  pause_task(inference_, inference_lock_);
  // Both tasks are paused and nothing was queued since: the worker-only state is ours.
  input_.stop_flushing();
  output_.stop_flushing();
  if (session_) {
    discard_in_flight();  // what the worker had in flight when it paused
    session_->reset();
  }
  previous_pts_ = GST_CLOCK_TIME_NONE;
  const bool ok = forward();
  gst_task_start(push_);
  gst_task_start(inference_);
  return ok;
}

bool FlowEngine::drain() { return input_.wait_drained() && output_.wait_drained(); }

FlowStats FlowEngine::stats() const {
  const std::lock_guard lock(lock_);
  return stats_;
}

double FlowEngine::announced_latency() const {
  const std::lock_guard lock(lock_);
  return stats_.announced_latency();
}

// ---- the inference worker ------------------------------------------------------------------

void FlowEngine::inference_loop(gpointer engine) { static_cast<FlowEngine*>(engine)->inference_step(); }
void FlowEngine::push_loop(gpointer engine) { static_cast<FlowEngine*>(engine)->push_step(); }

void FlowEngine::post(GstMessageType type, GQuark domain, gint code, const std::string& text,
                      const std::string& debug) {
  // No text: GStreamer's own wording for the code, as GST_ELEMENT_ERROR(…, (nullptr), …) gives.
  gst_element_message_full(element_, type, domain, code, text.empty() ? nullptr : g_strdup(text.c_str()),
                           debug.empty() ? nullptr : g_strdup(debug.c_str()), __FILE__, GST_FUNCTION, __LINE__);
}

void FlowEngine::error(GQuark domain, gint code, const std::string& text, const std::string& debug) {
  post(GST_MESSAGE_ERROR, domain, code, text, debug);
}

void FlowEngine::post_stats(const FlowStats& s) {
  const auto now = std::chrono::steady_clock::now();
  GstStructure* st = gst_structure_new(
      "neuflow-stats", "frames-in", G_TYPE_UINT64, s.frames_in(), "frames-processed", G_TYPE_UINT64, s.processed(),
      "flows", G_TYPE_UINT64, s.flows(), "frames-dropped", G_TYPE_UINT64, s.frames_dropped(), "mean-latency",
      G_TYPE_DOUBLE, s.mean_latency_ms(), "processing-rate", G_TYPE_DOUBLE, s.processing_rate(now), nullptr);
  gst_element_post_message(element_, gst_message_new_element(GST_OBJECT(element_), st));
}

void FlowEngine::post_drop(GstBuffer* dropped, const GstSegment& segment, guint64 processed, guint64 drops) {
  const GstClockTime pts = GST_BUFFER_PTS(dropped);
  GstMessage* msg = gst_message_new_qos(
      GST_OBJECT(element_), TRUE, gst_segment_to_running_time(&segment, GST_FORMAT_TIME, pts),
      gst_segment_to_stream_time(&segment, GST_FORMAT_TIME, pts), pts, GST_BUFFER_DURATION(dropped));
  gst_message_set_qos_stats(msg, GST_FORMAT_BUFFERS, processed, drops);
  gst_element_post_message(element_, msg);
}

bool FlowEngine::set_format(GstCaps* caps) {
  GstVideoInfo info;
  if (!gst_video_info_from_caps(&info, caps) || !converter_.set_format(info)) return false;
  // A frame size whose plan would not fit max-memory is refused here, at negotiation, with the
  // need and the limit, instead of at the first frame or by the kernel's OOM killer.
  if (session_) {
    if (auto problem = session_->memory_problem(GST_VIDEO_INFO_WIDTH(&info), GST_VIDEO_INFO_HEIGHT(&info))) {
      error(GST_CORE_ERROR, GST_CORE_ERROR_NEGOTIATION, *problem);
      return false;
    }
  }
  if (have_info_ && (GST_VIDEO_INFO_WIDTH(&info) != GST_VIDEO_INFO_WIDTH(&info_) ||
                     GST_VIDEO_INFO_HEIGHT(&info) != GST_VIDEO_INFO_HEIGHT(&info_))) {
    GST_INFO_OBJECT(element_, "frame size changed: the stream of flows starts anew");
    session_->reset();
  }
  info_ = info;
  have_info_ = true;
  return true;
}

// Hands the frame to the session (which may return before its flow is computed) and keeps its
// buffer in `in_flight_` until deliver_oldest() takes the flow.
GstFlowReturn FlowEngine::submit_frame(GstBuffer* buffer, guint64 frame_number) {
  if (!have_info_) {
    gst_buffer_unref(buffer);
    error(GST_CORE_ERROR, GST_CORE_ERROR_NEGOTIATION, "", "a frame arrived before its caps");
    return GST_FLOW_NOT_NEGOTIATED;
  }
  if (!session_) {
    gst_buffer_unref(buffer);
    error(GST_CORE_ERROR, GST_CORE_ERROR_STATE_CHANGE, "", "a frame arrived before the session was opened");
    return GST_FLOW_ERROR;
  }
  GstVideoFrame frame;
  if (!gst_video_frame_map(&frame, &info_, buffer, GST_MAP_READ)) {
    gst_buffer_unref(buffer);
    error(GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED, "could not map a video frame");
    return GST_FLOW_ERROR;
  }
  const auto started = std::chrono::steady_clock::now();
  try {
    session_->submit(converter_.view(frame));  // the pixels are copied (or used) before it returns
  } catch (const std::exception& e) {
    gst_video_frame_unmap(&frame);
    gst_buffer_unref(buffer);
    error(GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED, std::string("optical flow failed: ") + e.what());
    return GST_FLOW_ERROR;
  }
  gst_video_frame_unmap(&frame);
  in_flight_.push_back({buffer, frame_number, previous_pts_, previous_frame_, started});
  previous_pts_ = GST_BUFFER_PTS(buffer);
  previous_frame_ = frame_number;
  return GST_FLOW_OK;
}

// Takes the oldest frame's flow from the session and queues the frame (with its flow meta,
// except for the first frame of a stream) for the push task.
GstFlowReturn FlowEngine::deliver_oldest(const Settings& settings) {
  InFlight f = in_flight_.front();
  in_flight_.pop_front();
  std::optional<flow::FlowField> flow;
  try {
    flow = session_->take();
  } catch (const std::exception& e) {
    gst_buffer_unref(f.buffer);
    error(GST_STREAM_ERROR, GST_STREAM_ERROR_FAILED, std::string("optical flow failed: ") + e.what());
    return GST_FLOW_ERROR;
  }
  // The frame's own computation: from its submission, or from the delivery of the frame before
  // it where it was queued behind that one (the latency query adds the wait for that frame).
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - std::max(f.submitted, last_delivered_)).count();
  last_delivered_ = now;
  // backend=auto can leave the GPU at the first frame (its plan does not fit): say so once.
  if (session_->fallback_warning() != reported_fallback_) post_running_on_change();

  GstBuffer* buffer = f.buffer;
  if (flow) {
    buffer = attach_flow(buffer, *flow, {f.previous_pts, GST_BUFFER_PTS(buffer), f.previous_frame, f.frame},
                         session_->options(), seconds);
  }

  bool post = false, announce = false;
  FlowStats snapshot;
  {
    const std::lock_guard lock(lock_);
    announce = stats_.frame_out(flow.has_value(), seconds);
    if (stats_.message_due(std::chrono::steady_clock::now(), settings.stats_interval_ms)) {
      snapshot = stats_;
      post = true;
    }
  }
  if (post) post_stats(snapshot);
  if (announce) gst_element_post_message(element_, gst_message_new_latency(GST_OBJECT(element_)));
  Item out{buffer, nullptr, f.frame};
  // Waits while the push task is still busy with a result: a slow downstream slows us.
  if (output_.push_frame(out, Handoff::Policy::back_pressure) != Handoff::Result::queued) {
    gst_buffer_unref(buffer);  // flushing, or downstream failed: nobody takes it
  }
  return GST_FLOW_OK;
}

void FlowEngine::post_running_on_change() {
  reported_fallback_ = session_->fallback_warning();
  post(GST_MESSAGE_WARNING, GST_RESOURCE_ERROR, GST_RESOURCE_ERROR_FAILED, reported_fallback_);
  const std::lock_guard lock(lock_);
  running_on_ = session_->backend_description();
}

// Drops the frames in flight (a flush, a stop, a failure): their flows are taken and thrown
// away, so the session is idle and every buffer released.
void FlowEngine::discard_in_flight() {
  for (auto& f : in_flight_) {
    try {
      session_->take();
    } catch (const std::exception&) {
      // the frame is dropped either way; a failed device says so at the next frame
    }
    gst_buffer_unref(f.buffer);
  }
  in_flight_.clear();
}

// One item of `input_` per iteration, its result into `output_`.
void FlowEngine::inference_step() {
  auto entry = input_.take();
  if (!entry) {  // flushing: a flush or a stop pauses or stops this task
    discard_in_flight();
    gst_task_pause(inference_);
    return;
  }
  Item item = entry->value;
  GstFlowReturn ret = GST_FLOW_OK;
  const Settings settings = settings_();
  if (item.buffer) {
    ret = submit_frame(item.buffer, item.frame);
    // A frame stays in flight only while the next one is already waiting to overlap with it;
    // otherwise its flow is delivered now, so pipelining never adds latency to a live stream.
    while (ret == GST_FLOW_OK && !in_flight_.empty() &&
           (static_cast<int>(in_flight_.size()) >= session_->max_in_flight() || !input_.frame_waiting())) {
      ret = deliver_oldest(settings);
    }
    if (ret == GST_FLOW_OK && !in_flight_.empty()) {
      GST_LOG_OBJECT(element_, "frame %" G_GUINT64_FORMAT " in flight while the next one goes up",
                     in_flight_.back().frame);
    }
  } else {
    while (ret == GST_FLOW_OK && !in_flight_.empty()) ret = deliver_oldest(settings);  // events keep their place
  }
  if (!item.buffer && ret != GST_FLOW_OK) {
    gst_event_unref(item.event);
  } else if (!item.buffer) {
    if (GST_EVENT_TYPE(item.event) == GST_EVENT_CAPS) {
      GstCaps* caps = nullptr;
      gst_event_parse_caps(item.event, &caps);
      if (!set_format(caps)) {
        gchar* text = gst_caps_to_string(caps);
        error(GST_CORE_ERROR, GST_CORE_ERROR_NEGOTIATION, "", std::string("unusable caps ") + text);
        g_free(text);
        ret = GST_FLOW_NOT_NEGOTIATED;
      }
    }
    if (ret != GST_FLOW_OK || output_.push_other(item) != Handoff::Result::queued) gst_event_unref(item.event);
  }
  if (ret != GST_FLOW_OK) {
    // Our own failure (already posted as an element error): upstream learns it at its next
    // frame, downstream gets an end of stream after what was computed before. Recorded before
    // done(), so that a drain waiting on `input_` sees the failure, not an idle worker.
    GST_DEBUG_OBJECT(element_, "pausing inference: %s", gst_flow_get_name(ret));
    discard_in_flight();
    input_.fail(ret);
    Item eos{nullptr, gst_event_new_eos(), 0};
    if (output_.push_other(eos) != Handoff::Result::queued) gst_event_unref(eos.event);
    input_.done();
    gst_task_pause(inference_);
    return;
  }
  input_.done();
}

// ---- the push task -------------------------------------------------------------------------

// Pushes the worker's results downstream, in order.
void FlowEngine::push_step() {
  auto entry = output_.take();
  if (!entry) {
    gst_task_pause(push_);
    return;
  }
  Item item = entry->value;
  GstFlowReturn ret = GST_FLOW_OK;
  if (item.buffer) {
    ret = downstream_.push(item.buffer);
  } else if (!downstream_.push_event(item.event) && GST_EVENT_TYPE(item.event) == GST_EVENT_EOS) {
    GST_DEBUG_OBJECT(element_, "downstream refused EOS");
  }
  output_.done();
  if (ret != GST_FLOW_OK) {
    GST_DEBUG_OBJECT(element_, "pausing push: %s", gst_flow_get_name(ret));
    input_.fail(ret);
    output_.fail(ret);
    if (ret == GST_FLOW_NOT_LINKED || ret < GST_FLOW_EOS) {
      GST_ELEMENT_FLOW_ERROR(element_, ret);
      downstream_.push_event(gst_event_new_eos());
    }
    gst_task_pause(push_);
  }
}

}  // namespace neuflow::gst
