#pragma once
// The `neuflow` element's engine: everything it does between its pads, as a plain C++ class
// that tests drive without a pipeline. Three threads:
//
//   streaming thread ──chain()/queue_event()──▶ [input]  ──▶ inference worker (a GstTask)
//   inference worker ──results──────────────────▶ [output] ──▶ push task (a GstTask) ──▶ Downstream
//
// The streaming thread (upstream's) queues frames and serialized events in order; live, a frame
// still waiting is replaced by the newest (dropped with a QoS message), so upstream never waits
// for inference; every pair, upstream waits while two frames wait. The worker submits each
// frame to the session and keeps it in flight only while the next one already waits (on a GPU
// the next upload overlaps the pair before it; a live stream gains no latency). The push task
// hands results downstream, so the next frame computes while the last waits in a sink's clock
// sync. A downstream failure is recorded in both hand-offs and returned upstream by the next
// chain().
//
// The engine owns both tasks: start() starts them, flushes pause them, stop() stops and joins
// them (from any state, under load); the destructor stops them too. Errors, warnings, QoS,
// latency and stats messages are posted on the element given at construction.
#include <gst/gst.h>
#include <gst/video/video.h>

#include <chrono>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "flow_stats.hpp"
#include "frame_converter.hpp"
#include "frame_handoff.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::gst {

// Where the engine's results go: the element's src pad, or a test's recorder. Called from the
// push task only.
class Downstream {
 public:
  virtual ~Downstream() = default;
  virtual GstFlowReturn push(GstBuffer* buffer) = 0;  // takes the buffer
  virtual bool push_event(GstEvent* event) = 0;       // takes the event
};

class FlowEngine {
 public:
  // What the engine reads of the element's settings at each frame (under the element's lock).
  struct Settings {
    model::Behaviour behaviour = model::Behaviour::automatic;
    unsigned stats_interval_ms = 1000;  // between 'neuflow-stats' messages; 0: none
  };
  using SettingsSource = std::function<Settings()>;

  // `element`: where messages are posted (not owned, outlives the engine).
  FlowEngine(GstElement* element, Downstream& downstream, SettingsSource settings);
  ~FlowEngine();
  FlowEngine(const FlowEngine&) = delete;
  FlowEngine& operator=(const FlowEngine&) = delete;

  // ---- lifecycle (the element's state changes) ----
  // Opens the session (throws what FlowSession throws) and resets the counters. Only while stopped.
  void open(std::shared_ptr<const model::FlowModel> model, const model::SessionOptions& options);
  void close();  // drops the session; only while stopped
  // The session's backend ('cpu', 'vulkan device N (name)'), and its fallback warning.
  std::string running_on() const;
  std::string fallback_warning() const;

  // ---- the tasks (the element's src pad activation) ----
  bool start();  // both tasks started; false (and both stopped) when one could not start
  void stop();   // flushing, both tasks stopped and joined, frames in flight dropped

  // ---- the streaming thread ----
  // Queues a frame (takes it). `upstream_is_live` is asked once per stream when the behaviour
  // is automatic. Returns FLUSHING while flushing, else downstream's failure once there was one.
  GstFlowReturn chain(GstBuffer* buffer, const std::function<bool()>& upstream_is_live);
  // A serialized event, in stream order (takes it): CAPS is applied by the worker before the
  // frames after it, SEGMENT is remembered for QoS messages, STREAM_START asks liveness anew.
  // False when flushing (the event is released).
  bool queue_event(GstEvent* event);
  // A flush: begin_flush() wakes every waiter and drops what waits; the caller forwards
  // FLUSH_START downstream (unblocking a sink that holds the push task), then pause_for_flush()
  // returns once both tasks paused. end_flush() drops what was in flight, resets the stream,
  // calls `forward` (the caller pushes FLUSH_STOP downstream) and restarts the tasks; its
  // result is forward's. Stopped (not started), a flush only forwards.
  void begin_flush();
  void pause_for_flush();
  bool end_flush(const std::function<bool()>& forward);
  // Waits until every frame and event queued so far has been pushed (serialized queries must
  // not overtake them); false when a flush or a failure came first.
  bool drain();

  // ---- any thread ----
  FlowStats stats() const;
  double announced_latency() const;  // seconds per flow, 0 before the first flow

 private:
  // One entry of the ordered stream between the threads.
  struct Item {
    GstBuffer* buffer = nullptr;  // either a frame...
    GstEvent* event = nullptr;    // ...or a serialized event
    guint64 frame = 0;            // frame number (all frames in, dropped ones included)
  };
  using Handoff = FrameHandoff<Item>;
  // A frame submitted to the session and not yet taken; it holds its buffer.
  struct InFlight {
    GstBuffer* buffer;
    guint64 frame;
    GstClockTime previous_pts;  // the pair it closes, as it was when submitted
    guint64 previous_frame;
    std::chrono::steady_clock::time_point submitted;
  };

  static void release(Item& item);
  static void release_all(std::vector<Item> items);
  static void inference_loop(gpointer engine);
  static void push_loop(gpointer engine);

  void flush_handoffs();
  void stop_tasks();  // under tasks_lock_
  static void pause_task(GstTask* task, GRecMutex& lock);
  void inference_step();
  void push_step();
  bool set_format(GstCaps* caps);
  GstFlowReturn submit_frame(GstBuffer* buffer, guint64 frame_number);
  GstFlowReturn deliver_oldest(const Settings& settings);
  void discard_in_flight();
  void post(GstMessageType type, GQuark domain, gint code, const std::string& text, const std::string& debug = {});
  void error(GQuark domain, gint code, const std::string& text, const std::string& debug = {});
  void post_stats(const FlowStats& s);
  void post_drop(GstBuffer* dropped, const GstSegment& segment, guint64 processed, guint64 drops);
  void post_running_on_change();

  GstElement* element_;
  Downstream& downstream_;
  SettingsSource settings_;

  Handoff input_;
  Handoff output_;
  GstTask* inference_ = nullptr;  // owned; runs inference_loop
  GRecMutex inference_lock_;      // held by the task while it runs an iteration
  GstTask* push_ = nullptr;       // owned; runs push_loop
  GRecMutex push_lock_;
  // Serializes what starts, pauses and stops the tasks (activation, flushes): a flush that races
  // with a stop must not restart tasks that are being stopped.
  std::mutex tasks_lock_;
  bool active_ = false;  // started and not stopped: the tasks are ours to pause and restart

  mutable std::mutex lock_;   // guards what follows, up to the worker-only state
  std::optional<bool> live_;  // resolved from the behaviour and upstream's liveness
  GstSegment segment_{};
  FlowStats stats_;
  guint64 next_frame_ = 0;
  std::string running_on_;

  // Worker-only state: only the inference worker touches it while the tasks run; the other
  // threads only while they are paused or stopped (open, close, end_flush, stop).
  std::unique_ptr<model::FlowSession> session_;
  GstVideoInfo info_{};
  bool have_info_ = false;
  FrameConverter converter_;
  GstClockTime previous_pts_ = GST_CLOCK_TIME_NONE;
  guint64 previous_frame_ = 0;
  std::string reported_fallback_;  // the session's fallback warning, once posted
  std::deque<InFlight> in_flight_;
  std::chrono::steady_clock::time_point last_delivered_{};
};

}  // namespace neuflow::gst
