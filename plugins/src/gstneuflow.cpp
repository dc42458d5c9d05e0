/**
 * SECTION:element-neuflow
 *
 * Computes NeuFlow-V2 optical flow between consecutive video frames and attaches it to each
 * frame as a NeuflowFlowMeta (see neuflow/gst/flow_meta.h): the flow from the previous
 * processed frame to this one. Video passes through unchanged in any size and common raw
 * format; the element converts and pads or resizes internally.
 *
 * Inference runs on the element's own thread, and a second thread pushes its results
 * downstream, so the next frame is computed while the last one waits in a sink's clock sync
 * (no queue is needed after the element). In live mode (the default for live sources) the
 * streaming thread never waits for inference: a frame arriving while the previous one is still
 * queued replaces it (newest wins), the replaced frame is dropped and announced with a QoS
 * message, and the latency is reported in the LATENCY query. In every-pair mode (the
 * default for non-live sources) every frame is processed, upstream waits when two frames are
 * queued, and nothing is dropped. The first frame of a stream (and the first after a flush
 * or a size change) leaves without flow.
 *
 * ## Example launch lines
 * |[
 * gst-launch-1.0 v4l2src ! videoconvert ! neuflow model=neuflow_mixed.pth ! neuflowviz ! videoconvert ! autovideosink
 * gst-launch-1.0 filesrc location=in.mp4 ! decodebin ! videoconvert ! neuflow model=neuflow_mixed.pth ! neuflowsink location=flow_%05d.flo
 * ]|
 */
#include <gst/gst.h>
#include <gst/video/video.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "elements.hpp"
#include "flow_meta_attach.hpp"
#include "flow_stats.hpp"
#include "frame_converter.hpp"
#include "frame_handoff.hpp"
#include "neuflow/gst/flow_meta.h"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_debug);
#define GST_CAT_DEFAULT gst_neuflow_debug

namespace {

using neuflow::model::ChannelOrder;
using neuflow::model::FlowModel;
using neuflow::model::FlowSession;

enum class Behaviour { automatic, live, every_pair };

enum {
  PROP_0,
  PROP_MODEL,
  PROP_ITERS_S16,
  PROP_ITERS_S8,
  PROP_MODEL_WIDTH,
  PROP_MODEL_HEIGHT,
  PROP_THREADS,
  PROP_CHANNEL_ORDER,
  PROP_BACKEND,
  PROP_DEVICE,
  PROP_PRECISION,
  PROP_RUNNING_ON,
  PROP_BEHAVIOUR,
  PROP_STATS_INTERVAL,
  PROP_FRAMES_IN,
  PROP_FRAMES_PROCESSED,
  PROP_FLOWS,
  PROP_FRAMES_DROPPED,
  PROP_MEAN_LATENCY,
  PROP_PROCESSING_RATE,
};

// The session's settings, defaults and limits are the model's (neuflow/model/session_settings.hpp).
using SessionLimits = neuflow::model::SessionLimits;
constexpr neuflow::model::SessionOptions DEFAULT_SESSION{};
constexpr guint DEFAULT_STATS_INTERVAL = 1000;  // ms; 0 = no stats messages
constexpr std::size_t kEveryPairQueuedBuffers = 2;
// Results waiting for the push thread: one is enough to overlap a push with the next inference.
constexpr std::size_t kResultsWaiting = 1;

struct Settings {
  std::string model;
  neuflow::model::SessionOptions session = DEFAULT_SESSION;
  Behaviour behaviour = Behaviour::automatic;
  guint stats_interval = DEFAULT_STATS_INTERVAL;
  std::string running_on;  // read-only: the session's backend, once it exists
};

// One entry of the ordered stream between the streaming thread and the worker.
struct Item {
  GstBuffer *buffer = nullptr;  // either a frame...
  GstEvent *event = nullptr;    // ...or a serialized event
  guint64 frame = 0;            // frame number (all frames in, dropped ones included)
};

void release(Item &item) {
  if (item.buffer) gst_buffer_unref(item.buffer);
  if (item.event) gst_event_unref(item.event);
  item = {};
}

using Handoff = neuflow::gst::FrameHandoff<Item>;

void release_all(std::vector<Item> items) {
  for (auto &item : items) release(item);
}

// Three threads: the streaming thread queues frames and events in `input`; the inference
// worker (the element's own task) takes them in order, computes, and queues the results in
// `output`; the src pad's task pushes those downstream. A downstream failure (flushing, EOS,
// not linked) is recorded in both hand-offs and returned upstream from the next chain call.
struct State {
  Handoff input{kEveryPairQueuedBuffers};
  Handoff output{kResultsWaiting};
  GstTask *inference = nullptr;  // owned; runs inference_loop
  GRecMutex inference_lock;      // held by the task while it runs an iteration
  // Serializes what starts, pauses and stops the two tasks (activation, flushes): a flush that
  // races with the src pad's deactivation must not restart tasks that are being stopped.
  std::mutex tasks_lock;
  bool active = false;  // the src pad is active and its tasks are ours to pause and restart

  std::mutex lock;           // guards what follows, up to the worker-only state
  std::optional<bool> live;  // resolved from the behaviour and upstream's liveness
  GstSegment segment{};
  neuflow::gst::FlowStats stats;
  guint64 next_frame = 0;

  // Worker-only state (no lock needed: only the inference worker touches it while it runs;
  // the streaming thread only while the worker is paused, after a flush or stop).
  std::unique_ptr<FlowSession> session;
  GstVideoInfo info{};
  bool have_info = false;
  neuflow::gst::FrameConverter converter;
  GstClockTime previous_pts = GST_CLOCK_TIME_NONE;
  guint64 previous_frame = 0;
  std::string reported_fallback;  // the session's fallback warning, once posted
  // Frames submitted to the session and not yet taken, oldest first (FlowSession::submit: on
  // a GPU the next frame's upload overlaps the pair before it). Each holds its buffer.
  struct InFlight {
    GstBuffer *buffer;
    guint64 frame;
    GstClockTime previous_pts;  // the pair it closes, as it was when submitted
    guint64 previous_frame;
    std::chrono::steady_clock::time_point submitted;
  };
  std::deque<InFlight> in_flight;
  std::chrono::steady_clock::time_point last_delivered{};
};

}  // namespace

struct GstNeuflow {
  GstElement parent;
  GstPad *sinkpad;
  GstPad *srcpad;
  Settings *settings;  // under the object lock
  std::shared_ptr<const FlowModel> *model;
  State *state;
};

struct GstNeuflowClass {
  GstElementClass parent_class;
};

G_DEFINE_TYPE(GstNeuflow, gst_neuflow, GST_TYPE_ELEMENT)

#define GST_NEUFLOW(obj) (reinterpret_cast<GstNeuflow *>(obj))

namespace {

#define NEUFLOW_VIDEO_CAPS \
  GST_VIDEO_CAPS_MAKE("{ RGB, BGR, RGBx, BGRx, xRGB, xBGR, RGBA, BGRA, GRAY8, I420, NV12, YUY2 }")

GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(NEUFLOW_VIDEO_CAPS));
GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(NEUFLOW_VIDEO_CAPS));

GType channel_order_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(ChannelOrder::rgb), "RGB, the order the published weights were trained with", "rgb"},
      {static_cast<gint>(ChannelOrder::bgr), "BGR, as the reference demo scripts feed it", "bgr"},
      {0, nullptr, nullptr}};
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static("GstNeuflowChannelOrder", values));
  return type;
}

GType backend_get_type() {
  using neuflow::model::Backend;
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Backend::automatic), "the first discrete or integrated GPU (Vulkan), else the CPU", "auto"},
      {static_cast<gint>(Backend::cpu), "the CPU (oneDNN)", "cpu"},
      {static_cast<gint>(Backend::vulkan), "a Vulkan device (see 'device'), software ones included", "vulkan"},
      {0, nullptr, nullptr}};
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static("GstNeuflowBackend", values));
  return type;
}

GType precision_get_type() {
  using neuflow::model::Precision;
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Precision::fp32), "32-bit floats: exact to the reference", "fp32"},
      {static_cast<gint>(Precision::fp16), "16-bit storage on devices with shaderFloat16 (else fp32, with a warning)",
       "fp16"},
      {0, nullptr, nullptr}};
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static("GstNeuflowPrecision", values));
  return type;
}

GType behaviour_get_type() {
  static GType type = 0;
  static const GEnumValue values[] = {
      {static_cast<gint>(Behaviour::automatic), "live for live sources, every-pair otherwise", "auto"},
      {static_cast<gint>(Behaviour::live), "hold real-time: newest frame wins, late frames dropped", "live"},
      {static_cast<gint>(Behaviour::every_pair), "every consecutive pair, upstream waits, nothing dropped",
       "every-pair"},
      {0, nullptr, nullptr}};
  if (g_once_init_enter(&type)) g_once_init_leave(&type, g_enum_register_static("GstNeuflowBehaviour", values));
  return type;
}

Settings copy_settings(GstNeuflow *self) {
  GST_OBJECT_LOCK(self);
  Settings s = *self->settings;
  GST_OBJECT_UNLOCK(self);
  return s;
}

// Both hand-offs refuse new items and wake their waiters; what was waiting is released.
void flush_handoffs(State &st) {
  release_all(st.input.start_flushing());
  release_all(st.output.start_flushing());
}

// Pauses the inference worker and waits until it has: a started task holds its lock until it
// pauses, and the worker pauses itself at the next flush it sees.
void pause_inference(State &st) {
  gst_task_pause(st.inference);
  g_rec_mutex_lock(&st.inference_lock);
  g_rec_mutex_unlock(&st.inference_lock);
}

// ---- worker side ---------------------------------------------------------------------------

void post_stats(GstNeuflow *self, const neuflow::gst::FlowStats &s) {
  const auto now = std::chrono::steady_clock::now();
  GstStructure *st = gst_structure_new(
      "neuflow-stats", "frames-in", G_TYPE_UINT64, s.frames_in(), "frames-processed", G_TYPE_UINT64, s.processed(),
      "flows", G_TYPE_UINT64, s.flows(), "frames-dropped", G_TYPE_UINT64, s.frames_dropped(), "mean-latency",
      G_TYPE_DOUBLE, s.mean_latency_ms(), "processing-rate", G_TYPE_DOUBLE, s.processing_rate(now), nullptr);
  gst_element_post_message(GST_ELEMENT(self), gst_message_new_element(GST_OBJECT(self), st));
}

bool set_format(GstNeuflow *self, State &st, GstCaps *caps) {
  GstVideoInfo info;
  if (!gst_video_info_from_caps(&info, caps) || !st.converter.set_format(info)) return false;
  if (st.have_info && (GST_VIDEO_INFO_WIDTH(&info) != GST_VIDEO_INFO_WIDTH(&st.info) ||
                       GST_VIDEO_INFO_HEIGHT(&info) != GST_VIDEO_INFO_HEIGHT(&st.info))) {
    GST_INFO_OBJECT(self, "frame size changed: the stream of flows starts anew");
    st.session->reset();
  }
  st.info = info;
  st.have_info = true;
  return true;
}

// Hands the frame to the session (which may return before its flow is computed) and keeps
// its buffer in `in_flight` until deliver_oldest() takes the flow.
GstFlowReturn submit_frame(GstNeuflow *self, State &st, GstBuffer *buffer, guint64 frame_number) {
  if (!st.have_info) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, CORE, NEGOTIATION, (nullptr), ("a frame arrived before its caps"));
    return GST_FLOW_NOT_NEGOTIATED;
  }
  GstVideoFrame frame;
  if (!gst_video_frame_map(&frame, &st.info, buffer, GST_MAP_READ)) {
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("could not map a video frame"), (nullptr));
    return GST_FLOW_ERROR;
  }
  const auto started = std::chrono::steady_clock::now();
  try {
    st.session->submit(st.converter.view(frame));  // the pixels are copied (or used) before it returns
  } catch (const std::exception &e) {
    gst_video_frame_unmap(&frame);
    gst_buffer_unref(buffer);
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("optical flow failed: %s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
  gst_video_frame_unmap(&frame);
  st.in_flight.push_back({buffer, frame_number, st.previous_pts, st.previous_frame, started});
  st.previous_pts = GST_BUFFER_PTS(buffer);
  st.previous_frame = frame_number;
  return GST_FLOW_OK;
}

// Takes the oldest frame's flow from the session and queues the frame (with its flow meta,
// except for the first frame of a stream) for the push thread.
GstFlowReturn deliver_oldest(GstNeuflow *self, State &st, const Settings &settings) {
  State::InFlight f = st.in_flight.front();
  st.in_flight.pop_front();
  std::optional<neuflow::flow::FlowField> flow;
  try {
    flow = st.session->take();
  } catch (const std::exception &e) {
    gst_buffer_unref(f.buffer);
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("optical flow failed: %s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
  // The frame's own computation: from its submission, or from the delivery of the frame before
  // it where it was queued behind that one (the latency query adds the wait for that frame).
  const auto now = std::chrono::steady_clock::now();
  const double seconds = std::chrono::duration<double>(now - std::max(f.submitted, st.last_delivered)).count();
  st.last_delivered = now;
  // backend=auto can leave the GPU at the first frame (its plan does not fit): say so once.
  if (st.session->fallback_warning() != st.reported_fallback) {
    st.reported_fallback = st.session->fallback_warning();
    GST_ELEMENT_WARNING(self, RESOURCE, FAILED, ("%s", st.reported_fallback.c_str()), (nullptr));
    GST_OBJECT_LOCK(self);
    self->settings->running_on = st.session->backend_description();
    GST_OBJECT_UNLOCK(self);
  }

  GstBuffer *buffer = f.buffer;
  if (flow) {
    buffer =
        neuflow::gst::attach_flow(buffer, *flow, {f.previous_pts, GST_BUFFER_PTS(buffer), f.previous_frame, f.frame},
                                  st.session->options(), seconds);
  }

  bool post = false, announce = false;
  neuflow::gst::FlowStats snapshot;
  {
    const std::lock_guard lock(st.lock);
    announce = st.stats.frame_out(flow.has_value(), seconds);
    if (st.stats.message_due(std::chrono::steady_clock::now(), settings.stats_interval)) {
      snapshot = st.stats;
      post = true;
    }
  }
  if (post) post_stats(self, snapshot);
  if (announce) gst_element_post_message(GST_ELEMENT(self), gst_message_new_latency(GST_OBJECT(self)));
  Item out{buffer, nullptr, f.frame};
  // Waits while the push thread is still busy with a result: a slow downstream slows us.
  if (st.output.push_frame(out, Handoff::Policy::back_pressure) != Handoff::Result::queued) {
    gst_buffer_unref(buffer);  // flushing, or downstream failed: nobody takes it
  }
  return GST_FLOW_OK;
}

// Drops the frames in flight (a flush, a stop, a failure): their flows are taken and thrown
// away, so the session is idle and every buffer released.
void discard_in_flight(State &st) {
  for (auto &f : st.in_flight) {
    try {
      st.session->take();
    } catch (const std::exception &) {
      // the frame is dropped either way; a failed device says so at the next frame
    }
    gst_buffer_unref(f.buffer);
  }
  st.in_flight.clear();
}

// The inference worker: one item of `input` per iteration, its result into `output`.
void inference_loop(gpointer data) {
  auto *self = GST_NEUFLOW(data);
  State &st = *self->state;
  auto entry = st.input.take();
  if (!entry) {  // flushing: a flush or a stop pauses or stops this task
    discard_in_flight(st);
    gst_task_pause(st.inference);
    return;
  }
  Item item = entry->value;
  GstFlowReturn ret = GST_FLOW_OK;
  const Settings settings = copy_settings(self);
  if (item.buffer) {
    ret = submit_frame(self, st, item.buffer, item.frame);
    // A frame stays in flight only while the next one is already waiting to overlap with it;
    // otherwise its flow is delivered now, so pipelining never adds latency to a live stream.
    while (ret == GST_FLOW_OK && !st.in_flight.empty() &&
           (static_cast<int>(st.in_flight.size()) >= st.session->max_in_flight() || !st.input.frame_waiting())) {
      ret = deliver_oldest(self, st, settings);
    }
    if (ret == GST_FLOW_OK && !st.in_flight.empty()) {
      GST_LOG_OBJECT(self, "frame %" G_GUINT64_FORMAT " in flight while the next one goes up",
                     st.in_flight.back().frame);
    }
  } else {
    while (ret == GST_FLOW_OK && !st.in_flight.empty())
      ret = deliver_oldest(self, st, settings);  // events keep their place
  }
  if (!item.buffer && ret != GST_FLOW_OK) {
    gst_event_unref(item.event);
  } else if (!item.buffer) {
    if (GST_EVENT_TYPE(item.event) == GST_EVENT_CAPS) {
      GstCaps *caps = nullptr;
      gst_event_parse_caps(item.event, &caps);
      if (!set_format(self, st, caps)) {
        gchar *text = gst_caps_to_string(caps);
        GST_ELEMENT_ERROR(self, CORE, NEGOTIATION, (nullptr), ("unusable caps %s", text));
        g_free(text);
        ret = GST_FLOW_NOT_NEGOTIATED;
      }
    }
    if (ret != GST_FLOW_OK || st.output.push_other(item) != Handoff::Result::queued) gst_event_unref(item.event);
  }
  if (ret != GST_FLOW_OK) {
    // Our own failure (already posted as an element error): upstream learns it at its next
    // frame, downstream gets an end of stream after what was computed before. Recorded before
    // done(), so that a drain waiting on `input` sees the failure, not an idle worker.
    GST_DEBUG_OBJECT(self, "pausing inference: %s", gst_flow_get_name(ret));
    discard_in_flight(st);
    st.input.fail(ret);
    Item eos{nullptr, gst_event_new_eos(), 0};
    if (st.output.push_other(eos) != Handoff::Result::queued) gst_event_unref(eos.event);
    st.input.done();
    gst_task_pause(st.inference);
    return;
  }
  st.input.done();
}

// The src pad's task: pushes the worker's results downstream, in order.
void push_loop(gpointer data) {
  auto *self = GST_NEUFLOW(data);
  State &st = *self->state;
  auto entry = st.output.take();
  if (!entry) {
    gst_pad_pause_task(self->srcpad);
    return;
  }
  Item item = entry->value;
  GstFlowReturn ret = GST_FLOW_OK;
  if (item.buffer) {
    ret = gst_pad_push(self->srcpad, item.buffer);
  } else if (!gst_pad_push_event(self->srcpad, item.event) && GST_EVENT_TYPE(item.event) == GST_EVENT_EOS) {
    GST_DEBUG_OBJECT(self, "downstream refused EOS");
  }
  st.output.done();
  if (ret != GST_FLOW_OK) {
    GST_DEBUG_OBJECT(self, "pausing push: %s", gst_flow_get_name(ret));
    st.input.fail(ret);
    st.output.fail(ret);
    if (ret == GST_FLOW_NOT_LINKED || ret < GST_FLOW_EOS) {
      GST_ELEMENT_FLOW_ERROR(self, ret);
      gst_pad_push_event(self->srcpad, gst_event_new_eos());
    }
    gst_pad_pause_task(self->srcpad);
  }
}

// ---- streaming-thread side -----------------------------------------------------------------

bool upstream_is_live(GstNeuflow *self) {
  GstQuery *query = gst_query_new_latency();
  gboolean live = FALSE;
  if (gst_pad_peer_query(self->sinkpad, query)) gst_query_parse_latency(query, &live, nullptr, nullptr);
  gst_query_unref(query);
  return live;
}

void post_drop(GstNeuflow *self, GstBuffer *dropped, const GstSegment &segment, guint64 processed, guint64 drops) {
  const GstClockTime pts = GST_BUFFER_PTS(dropped);
  GstMessage *msg = gst_message_new_qos(
      GST_OBJECT(self), TRUE, gst_segment_to_running_time(&segment, GST_FORMAT_TIME, pts),
      gst_segment_to_stream_time(&segment, GST_FORMAT_TIME, pts), pts, GST_BUFFER_DURATION(dropped));
  gst_message_set_qos_stats(msg, GST_FORMAT_BUFFERS, processed, drops);
  gst_element_post_message(GST_ELEMENT(self), msg);
}

GstFlowReturn sink_chain(GstPad * /*pad*/, GstObject *parent, GstBuffer *buffer) {
  auto *self = GST_NEUFLOW(parent);
  State &st = *self->state;
  std::optional<bool> live;
  {
    const std::lock_guard lock(st.lock);
    live = st.live;
  }
  if (!live) {
    const Behaviour b = copy_settings(self).behaviour;
    const bool resolved = b == Behaviour::automatic ? upstream_is_live(self) : b == Behaviour::live;
    GST_INFO_OBJECT(self, "behaviour: %s", resolved ? "live" : "every-pair");
    const std::lock_guard lock(st.lock);
    st.live = live = resolved;
  }

  // Newest wins when live: a frame still waiting for the worker is replaced by this one (the
  // hand-off never waits then, so it happens under the counters' lock and they never show a
  // frame in that is neither waiting, computed nor dropped); its QoS message is posted after.
  // Every pair: wait for room, outside the lock.
  Item item{buffer, nullptr, 0};
  std::vector<Item> dropped;
  Handoff::Result queued;
  guint64 processed = 0, drops = 0;
  GstSegment segment{};
  if (*live) {
    const std::lock_guard lock(st.lock);
    st.stats.frame_in();
    item.frame = st.next_frame++;
    queued = st.input.push_frame(item, Handoff::Policy::newest_wins, &dropped);
    st.stats.dropped(dropped.size());
    processed = st.stats.processed();
    drops = st.stats.frames_dropped();
    segment = st.segment;
  } else {
    {
      const std::lock_guard lock(st.lock);
      st.stats.frame_in();
      item.frame = st.next_frame++;
    }
    queued = st.input.push_frame(item, Handoff::Policy::back_pressure);
  }
  if (!dropped.empty()) {
    for (Item &old : dropped) {
      post_drop(self, old.buffer, segment, processed, drops);
      release(old);
    }
  }
  if (queued == Handoff::Result::queued) return GST_FLOW_OK;
  gst_buffer_unref(buffer);
  return queued == Handoff::Result::flushing ? GST_FLOW_FLUSHING : static_cast<GstFlowReturn>(st.input.failure());
}

gboolean sink_event(GstPad *pad, GstObject *parent, GstEvent *event) {
  auto *self = GST_NEUFLOW(parent);
  State &st = *self->state;
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_FLUSH_START: {
      flush_handoffs(st);
      const gboolean ok = gst_pad_push_event(self->srcpad, event);  // unblocks a sink holding the push thread
      const std::lock_guard tasks(st.tasks_lock);
      if (st.active) {
        gst_pad_pause_task(self->srcpad);  // returns once the push thread finished its current item
        pause_inference(st);               // returns once the worker finished its current item
      }
      return ok;
    }
    case GST_EVENT_FLUSH_STOP: {
      const std::lock_guard tasks(st.tasks_lock);
      if (!st.active) return gst_pad_push_event(self->srcpad, event);  // being stopped: stays flushing
      // Paused again (idempotent): a FLUSH_STOP may come without its FLUSH_START, and a worker
      // that saw the flush must not pause itself after the restart below.
      flush_handoffs(st);
      gst_pad_pause_task(self->srcpad);
      pause_inference(st);
      // Both threads are paused and nothing was queued since: the worker-only state is ours.
      st.input.stop_flushing();
      st.output.stop_flushing();
      if (st.session) {
        discard_in_flight(st);  // what the worker had in flight when it paused
        st.session->reset();
      }
      st.previous_pts = GST_CLOCK_TIME_NONE;
      const gboolean ok = gst_pad_push_event(self->srcpad, event);
      gst_pad_start_task(self->srcpad, push_loop, self, nullptr);
      gst_task_start(st.inference);
      return ok;
    }
    case GST_EVENT_CAPS: {
      GstCaps *caps = nullptr;
      gst_event_parse_caps(event, &caps);
      GstVideoInfo info;
      if (!gst_video_info_from_caps(&info, caps)) {
        gst_event_unref(event);
        return FALSE;
      }
      break;  // queued below, applied by the worker in stream order
    }
    case GST_EVENT_SEGMENT: {
      const GstSegment *segment = nullptr;
      gst_event_parse_segment(event, &segment);
      const std::lock_guard lock(st.lock);
      gst_segment_copy_into(segment, &st.segment);
      break;
    }
    case GST_EVENT_STREAM_START: {
      const std::lock_guard lock(st.lock);
      st.live.reset();  // a new stream may come from a source of another kind
      break;
    }
    default:
      break;
  }
  if (!GST_EVENT_IS_SERIALIZED(event)) return gst_pad_event_default(pad, parent, event);
  Item item{nullptr, event, 0};
  if (st.input.push_other(item) != Handoff::Result::queued) {
    gst_event_unref(event);
    return FALSE;
  }
  return TRUE;
}

gboolean sink_query(GstPad *pad, GstObject *parent, GstQuery *query) {
  auto *self = GST_NEUFLOW(parent);
  State &st = *self->state;
  if (GST_QUERY_IS_SERIALIZED(query)) {
    // Serialized queries (allocation, drain) must not overtake the frames queued before them:
    // the worker has computed them all, then the push thread has pushed them all.
    if (!st.input.wait_drained() || !st.output.wait_drained()) return FALSE;
  }
  return gst_pad_query_default(pad, parent, query);
}

gboolean src_query(GstPad *pad, GstObject *parent, GstQuery *query) {
  auto *self = GST_NEUFLOW(parent);
  if (GST_QUERY_TYPE(query) != GST_QUERY_LATENCY) return gst_pad_query_default(pad, parent, query);
  if (!gst_pad_peer_query(self->sinkpad, query)) return FALSE;
  gboolean live = FALSE;
  GstClockTime min = 0, max = GST_CLOCK_TIME_NONE;
  gst_query_parse_latency(query, &live, &min, &max);
  State &st = *self->state;
  double per_frame = 0;
  {
    const std::lock_guard lock(st.lock);
    per_frame = st.stats.announced_latency();
  }
  // A frame waits at most for the one being computed, then for its own computation.
  const auto ours = static_cast<GstClockTime>(2 * per_frame * GST_SECOND);
  min += ours;
  if (GST_CLOCK_TIME_IS_VALID(max)) max += ours;
  gst_query_set_latency(query, live, min, max);
  return TRUE;
}

gboolean src_activate_mode(GstPad *pad, GstObject *parent, GstPadMode mode, gboolean active) {
  auto *self = GST_NEUFLOW(parent);
  State &st = *self->state;
  if (mode != GST_PAD_MODE_PUSH) return FALSE;
  const std::lock_guard tasks(st.tasks_lock);
  if (active) {
    st.input.stop_flushing();
    st.output.stop_flushing();
    if (gst_task_start(st.inference) && gst_pad_start_task(pad, push_loop, self, nullptr)) {
      st.active = true;
      return TRUE;
    }
  }
  // Deactivation, or an activation that could not start both tasks: both stopped and joined.
  st.active = false;
  flush_handoffs(st);
  const gboolean stopped = gst_pad_stop_task(pad);
  // A started task holds its lock until it pauses: the worker pauses itself once it sees the
  // flush. Stopped under the lock, it cannot pause itself again after the stop, which would
  // leave the join waiting.
  g_rec_mutex_lock(&st.inference_lock);
  gst_task_stop(st.inference);
  g_rec_mutex_unlock(&st.inference_lock);
  gst_task_join(st.inference);
  return active ? FALSE : stopped;
}

// ---- lifecycle -----------------------------------------------------------------------------

GstStateChangeReturn change_state(GstElement *element, GstStateChange transition) {
  auto *self = GST_NEUFLOW(element);
  State &st = *self->state;
  switch (transition) {
    case GST_STATE_CHANGE_NULL_TO_READY: {
      const Settings s = copy_settings(self);
      if (s.model.empty()) {
        GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("no model given"),
                          ("set the 'model' property to a NeuFlow-V2 checkpoint (.pth)"));
        return GST_STATE_CHANGE_FAILURE;
      }
      try {
        *self->model = FlowModel::load_shared(s.model);
      } catch (const std::exception &e) {
        GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ, ("cannot load the model: %s", e.what()), (nullptr));
        return GST_STATE_CHANGE_FAILURE;
      }
      break;
    }
    case GST_STATE_CHANGE_READY_TO_PAUSED: {
      const Settings s = copy_settings(self);
      try {
        st.session = std::make_unique<FlowSession>(*self->model, s.session);
      } catch (const neuflow::model::BackendError &e) {
        GST_ELEMENT_ERROR(self, RESOURCE, FAILED, ("cannot run on the GPU: %s", e.what()),
                          ("backend=%s device=%d; `neuflow devices` lists the Vulkan devices",
                           std::string(neuflow::model::backend_name(s.session.backend)).c_str(), s.session.device));
        return GST_STATE_CHANGE_FAILURE;
      } catch (const std::exception &e) {
        GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("invalid settings: %s", e.what()), (nullptr));
        return GST_STATE_CHANGE_FAILURE;
      }
      st.reported_fallback = st.session->fallback_warning();
      if (!st.reported_fallback.empty()) {
        GST_ELEMENT_WARNING(self, RESOURCE, FAILED, ("%s", st.reported_fallback.c_str()), (nullptr));
      }
      GST_INFO_OBJECT(self, "running on %s", st.session->backend_description().c_str());
      GST_OBJECT_LOCK(self);
      self->settings->running_on = st.session->backend_description();
      GST_OBJECT_UNLOCK(self);
      const std::lock_guard lock(st.lock);
      st.stats.restart(std::chrono::steady_clock::now());
      st.next_frame = 0;
      st.live.reset();
      st.have_info = false;
      st.previous_pts = GST_CLOCK_TIME_NONE;
      gst_segment_init(&st.segment, GST_FORMAT_TIME);
      break;
    }
    default:
      break;
  }

  const GstStateChangeReturn ret = GST_ELEMENT_CLASS(gst_neuflow_parent_class)->change_state(element, transition);
  if (ret == GST_STATE_CHANGE_FAILURE) return ret;

  switch (transition) {
    case GST_STATE_CHANGE_PAUSED_TO_READY:  // pads are deactivated: the worker has stopped
      if (st.session) discard_in_flight(st);
      st.session.reset();
      st.have_info = false;
      break;
    case GST_STATE_CHANGE_READY_TO_NULL:
      self->model->reset();
      break;
    default:
      break;
  }
  return ret;
}

void set_property(GObject *object, guint id, const GValue *value, GParamSpec *pspec) {
  auto *self = GST_NEUFLOW(object);
  GST_OBJECT_LOCK(self);
  Settings &s = *self->settings;
  switch (id) {
    case PROP_MODEL:
      s.model = g_value_get_string(value) ? g_value_get_string(value) : "";
      break;
    // The param specs' ranges keep each value within int.
    case PROP_ITERS_S16:
      s.session.iterations.s16 = static_cast<int>(g_value_get_uint(value));
      break;
    case PROP_ITERS_S8:
      s.session.iterations.s8 = static_cast<int>(g_value_get_uint(value));
      break;
    case PROP_MODEL_WIDTH:
      s.session.model_width = static_cast<int>(g_value_get_uint(value));
      break;
    case PROP_MODEL_HEIGHT:
      s.session.model_height = static_cast<int>(g_value_get_uint(value));
      break;
    case PROP_THREADS:
      s.session.threads = static_cast<int>(g_value_get_uint(value));
      break;
    case PROP_CHANNEL_ORDER:
      s.session.network_order = static_cast<ChannelOrder>(g_value_get_enum(value));
      break;
    case PROP_BACKEND:
      s.session.backend = static_cast<neuflow::model::Backend>(g_value_get_enum(value));
      break;
    case PROP_DEVICE:
      s.session.device = g_value_get_int(value);
      break;
    case PROP_PRECISION:
      s.session.precision = static_cast<neuflow::model::Precision>(g_value_get_enum(value));
      break;
    case PROP_BEHAVIOUR:
      s.behaviour = static_cast<Behaviour>(g_value_get_enum(value));
      break;
    case PROP_STATS_INTERVAL:
      s.stats_interval = g_value_get_uint(value);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

void get_property(GObject *object, guint id, GValue *value, GParamSpec *pspec) {
  auto *self = GST_NEUFLOW(object);
  if (id >= PROP_FRAMES_IN) {
    State &st = *self->state;
    const std::lock_guard lock(st.lock);
    const neuflow::gst::FlowStats &s = st.stats;
    switch (id) {
      case PROP_FRAMES_IN:
        g_value_set_uint64(value, s.frames_in());
        break;
      case PROP_FRAMES_PROCESSED:
        g_value_set_uint64(value, s.processed());
        break;
      case PROP_FLOWS:
        g_value_set_uint64(value, s.flows());
        break;
      case PROP_FRAMES_DROPPED:
        g_value_set_uint64(value, s.frames_dropped());
        break;
      case PROP_MEAN_LATENCY:
        g_value_set_double(value, s.mean_latency_ms());
        break;
      case PROP_PROCESSING_RATE:
        g_value_set_double(value, s.processing_rate(std::chrono::steady_clock::now()));
        break;
      default:
        G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
        break;
    }
    return;
  }
  GST_OBJECT_LOCK(self);
  const Settings &s = *self->settings;
  switch (id) {
    case PROP_MODEL:
      g_value_set_string(value, s.model.c_str());
      break;
    case PROP_ITERS_S16:
      g_value_set_uint(value, static_cast<guint>(s.session.iterations.s16));
      break;
    case PROP_ITERS_S8:
      g_value_set_uint(value, static_cast<guint>(s.session.iterations.s8));
      break;
    case PROP_MODEL_WIDTH:
      g_value_set_uint(value, static_cast<guint>(s.session.model_width));
      break;
    case PROP_MODEL_HEIGHT:
      g_value_set_uint(value, static_cast<guint>(s.session.model_height));
      break;
    case PROP_THREADS:
      g_value_set_uint(value, static_cast<guint>(s.session.threads));
      break;
    case PROP_CHANNEL_ORDER:
      g_value_set_enum(value, static_cast<gint>(s.session.network_order));
      break;
    case PROP_BACKEND:
      g_value_set_enum(value, static_cast<gint>(s.session.backend));
      break;
    case PROP_DEVICE:
      g_value_set_int(value, s.session.device);
      break;
    case PROP_PRECISION:
      g_value_set_enum(value, static_cast<gint>(s.session.precision));
      break;
    case PROP_RUNNING_ON:
      g_value_set_string(value, s.running_on.c_str());
      break;
    case PROP_BEHAVIOUR:
      g_value_set_enum(value, static_cast<gint>(s.behaviour));
      break;
    case PROP_STATS_INTERVAL:
      g_value_set_uint(value, s.stats_interval);
      break;
    default:
      G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec);
      break;
  }
  GST_OBJECT_UNLOCK(self);
}

void finalize(GObject *object) {
  auto *self = GST_NEUFLOW(object);
  flush_handoffs(*self->state);
  gst_object_unref(self->state->inference);
  g_rec_mutex_clear(&self->state->inference_lock);
  delete self->state;
  delete self->model;
  delete self->settings;
  G_OBJECT_CLASS(gst_neuflow_parent_class)->finalize(object);
}

}  // namespace

static void gst_neuflow_class_init(GstNeuflowClass *klass) {
  auto *gobject_class = G_OBJECT_CLASS(klass);
  auto *element_class = GST_ELEMENT_CLASS(klass);
  gobject_class->set_property = set_property;
  gobject_class->get_property = get_property;
  gobject_class->finalize = finalize;
  element_class->change_state = change_state;

  constexpr auto rw = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);
  constexpr auto ro = static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS);
  // The model is loaded when the element leaves NULL, so it can only change in NULL.
  constexpr auto rw_null = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
  g_object_class_install_property(
      gobject_class, PROP_MODEL,
      g_param_spec_string("model", "Model",
                          "NeuFlow-V2 checkpoint (.pth), e.g. neuflow_mixed.pth; loaded once when "
                          "the element leaves NULL and shared with other elements using the same file",
                          nullptr, rw_null));
  g_object_class_install_property(
      gobject_class, PROP_ITERS_S16,
      g_param_spec_uint("iters-s16", "Iterations at 1/16", "Refinement iterations at 1/16 resolution", 0,
                        SessionLimits::max_iterations_s16, DEFAULT_SESSION.iterations.s16, rw));
  g_object_class_install_property(
      gobject_class, PROP_ITERS_S8,
      g_param_spec_uint("iters-s8", "Iterations at 1/8", "Refinement iterations at 1/8 resolution", 0,
                        SessionLimits::max_iterations_s8, DEFAULT_SESSION.iterations.s8, rw));
  g_object_class_install_property(
      gobject_class, PROP_MODEL_WIDTH,
      g_param_spec_uint("model-width", "Model width",
                        "Width the network runs at (multiple of 16); 0: the frame's own size, edge-padded", 0,
                        SessionLimits::max_side, DEFAULT_SESSION.model_width, rw));
  g_object_class_install_property(
      gobject_class, PROP_MODEL_HEIGHT,
      g_param_spec_uint("model-height", "Model height",
                        "Height the network runs at (multiple of 16); 0: the frame's own size, edge-padded", 0,
                        SessionLimits::max_side, DEFAULT_SESSION.model_height, rw));
  g_object_class_install_property(gobject_class, PROP_THREADS,
                                  g_param_spec_uint("threads", "Threads", "CPU threads for inference (0: all cores)", 0,
                                                    SessionLimits::max_threads, DEFAULT_SESSION.threads, rw));
  g_object_class_install_property(
      gobject_class, PROP_CHANNEL_ORDER,
      g_param_spec_enum("channel-order", "Channel order", "Colour order fed to the network", channel_order_get_type(),
                        static_cast<gint>(DEFAULT_SESSION.network_order), rw));
  g_object_class_install_property(
      gobject_class, PROP_BACKEND,
      g_param_spec_enum("backend", "Backend",
                        "Where the network runs: auto (the first discrete or integrated GPU through Vulkan, else the "
                        "CPU, with a warning when a GPU fails), cpu, or vulkan (fails without a Vulkan device)",
                        backend_get_type(), static_cast<gint>(DEFAULT_SESSION.backend), rw));
  g_object_class_install_property(
      gobject_class, PROP_DEVICE,
      g_param_spec_int("device", "Device",
                       "Vulkan device index as `neuflow devices` lists them; -1: the first discrete or integrated GPU",
                       -1, SessionLimits::max_device, DEFAULT_SESSION.device, rw));
  g_object_class_install_property(
      gobject_class, PROP_PRECISION,
      g_param_spec_enum("precision", "Precision",
                        "What a Vulkan device stores tensors in (the CPU computes in fp32 either way)",
                        precision_get_type(), static_cast<gint>(DEFAULT_SESSION.precision), rw));
  g_object_class_install_property(
      gobject_class, PROP_RUNNING_ON,
      g_param_spec_string("running-on", "Running on",
                          "Where the network runs, once the element is PAUSED: 'cpu' or 'vulkan device N (name)'", "",
                          ro));
  g_object_class_install_property(
      gobject_class, PROP_BEHAVIOUR,
      g_param_spec_enum("behaviour", "Behaviour",
                        "live: hold real-time by dropping frames; every-pair: compute every consecutive pair",
                        behaviour_get_type(), static_cast<gint>(Behaviour::automatic), rw));
  g_object_class_install_property(
      gobject_class, PROP_STATS_INTERVAL,
      g_param_spec_uint(
          "stats-interval", "Stats interval",
          "Milliseconds between 'neuflow-stats' element messages carrying the counters (0: none)", 0, G_MAXUINT,
          DEFAULT_STATS_INTERVAL,
          static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING)));
  g_object_class_install_property(
      gobject_class, PROP_FRAMES_IN,
      g_param_spec_uint64("frames-in", "Frames in", "Frames received", 0, G_MAXUINT64, 0, ro));
  g_object_class_install_property(
      gobject_class, PROP_FRAMES_PROCESSED,
      g_param_spec_uint64("frames-processed", "Frames processed",
                          "Frames computed, the first of a stream (which has no flow yet) included", 0, G_MAXUINT64, 0,
                          ro));
  g_object_class_install_property(
      gobject_class, PROP_FLOWS,
      g_param_spec_uint64("flows", "Flows",
                          "Frames that left with a flow (frames-processed less the first frame of each stream, "
                          "of each flush and of each size change)",
                          0, G_MAXUINT64, 0, ro));
  g_object_class_install_property(
      gobject_class, PROP_FRAMES_DROPPED,
      g_param_spec_uint64("frames-dropped", "Frames dropped", "Frames dropped to hold real-time (live behaviour)", 0,
                          G_MAXUINT64, 0, ro));
  g_object_class_install_property(
      gobject_class, PROP_MEAN_LATENCY,
      g_param_spec_double("mean-latency", "Mean latency", "Mean inference time per flow, milliseconds", 0, G_MAXDOUBLE,
                          0, ro));
  g_object_class_install_property(gobject_class, PROP_PROCESSING_RATE,
                                  g_param_spec_double("processing-rate", "Processing rate",
                                                      "Frames leaving the element per second", 0, G_MAXDOUBLE, 0, ro));

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(element_class, "NeuFlow-V2 optical flow", "Filter/Analyzer/Video",
                                        "Computes optical flow between video frames and attaches it as metadata",
                                        "neuflow");
  gst_element_class_add_static_metadata(element_class, GST_ELEMENT_METADATA_DOC_URI, NEUFLOW_DOC_URI);
  gst_type_mark_as_plugin_api(channel_order_get_type(), static_cast<GstPluginAPIFlags>(0));
  gst_type_mark_as_plugin_api(behaviour_get_type(), static_cast<GstPluginAPIFlags>(0));
  gst_type_mark_as_plugin_api(backend_get_type(), static_cast<GstPluginAPIFlags>(0));
  gst_type_mark_as_plugin_api(precision_get_type(), static_cast<GstPluginAPIFlags>(0));
  GST_DEBUG_CATEGORY_INIT(gst_neuflow_debug, "neuflow", 0, "NeuFlow-V2 optical flow element");
}

static void gst_neuflow_init(GstNeuflow *self) {
  self->settings = new Settings();
  self->model = new std::shared_ptr<const FlowModel>();
  self->state = new State();
  gst_segment_init(&self->state->segment, GST_FORMAT_TIME);
  // Flushing until the src pad is activated.
  flush_handoffs(*self->state);
  g_rec_mutex_init(&self->state->inference_lock);
  self->state->inference = gst_task_new(inference_loop, self, nullptr);
  gst_task_set_lock(self->state->inference, &self->state->inference_lock);

  self->sinkpad = gst_pad_new_from_static_template(&sink_template, "sink");
  gst_pad_set_chain_function(self->sinkpad, sink_chain);
  gst_pad_set_event_function(self->sinkpad, sink_event);
  gst_pad_set_query_function(self->sinkpad, sink_query);
  GST_PAD_SET_PROXY_CAPS(self->sinkpad);
  gst_element_add_pad(GST_ELEMENT(self), self->sinkpad);

  self->srcpad = gst_pad_new_from_static_template(&src_template, "src");
  gst_pad_set_query_function(self->srcpad, src_query);
  gst_pad_set_activatemode_function(self->srcpad, src_activate_mode);
  GST_PAD_SET_PROXY_CAPS(self->srcpad);
  gst_element_add_pad(GST_ELEMENT(self), self->srcpad);
}

GST_ELEMENT_REGISTER_DEFINE(neuflow, "neuflow", GST_RANK_NONE, gst_neuflow_get_type());
