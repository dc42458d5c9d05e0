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
// The GObject side only: pads, properties, events, queries and state changes. What happens
// between the pads (the threads, frames in flight, pushing) is FlowEngine (flow_engine.hpp).
#include <gst/gst.h>
#include <gst/video/video.h>

#include <chrono>
#include <memory>
#include <string>

#include "elements.hpp"
#include "flow_engine.hpp"
#include "gstneuflow_enums.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "neuflow/model/session_option_docs.hpp"
#include "neuflow/model/session_settings.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_debug);
#define GST_CAT_DEFAULT gst_neuflow_debug

namespace {

using neuflow::gst::FlowEngine;
using neuflow::model::Backend;
using neuflow::model::Behaviour;
using neuflow::model::ChannelOrder;
using neuflow::model::FlowModel;
using neuflow::model::Precision;
using neuflow::model::SessionLimits;
namespace docs = neuflow::model::option_docs;

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
  PROP_MAX_MEMORY,
  PROP_RUNNING_ON,
  PROP_BEHAVIOUR,
  PROP_STATS_INTERVAL,
  PROP_FRAMES_IN,
  PROP_FRAMES_PROCESSED,
  PROP_FLOWS,
  PROP_FRAMES_DROPPED,
  PROP_MEAN_LATENCY,
  PROP_PROCESSING_RATE
};

// The session's settings, defaults and limits are the model's (neuflow/model/session_settings.hpp).
constexpr neuflow::model::SessionOptions DEFAULT_PROP_SESSION{};
constexpr Behaviour DEFAULT_PROP_BEHAVIOUR = Behaviour::automatic;
constexpr guint DEFAULT_PROP_STATS_INTERVAL = 1000;  // ms; 0 = no stats messages

// The properties, under the object lock.
struct Settings {
  std::string model;
  neuflow::model::SessionOptions session = DEFAULT_PROP_SESSION;
  Behaviour behaviour = DEFAULT_PROP_BEHAVIOUR;
  guint stats_interval = DEFAULT_PROP_STATS_INTERVAL;
};

}  // namespace

struct GstNeuflowPrivate;

struct GstNeuflow {
  GstElement parent;
  GstPad *sinkpad;
  GstPad *srcpad;
  GstNeuflowPrivate *priv;  // created in init, destroyed in finalize
};

struct GstNeuflowClass {
  GstElementClass parent_class;
};

// Results leave through the src pad.
class SrcPadDownstream : public neuflow::gst::Downstream {
 public:
  explicit SrcPadDownstream(GstPad *pad) : pad_(pad) {}
  GstFlowReturn push(GstBuffer *buffer) override { return gst_pad_push(pad_, buffer); }
  bool push_event(GstEvent *event) override { return gst_pad_push_event(pad_, event); }

 private:
  GstPad *pad_;
};

struct GstNeuflowPrivate {
  explicit GstNeuflowPrivate(GstNeuflow *self)
      : downstream(self->srcpad), engine(GST_ELEMENT(self), downstream, [self] { return engine_settings(self); }) {}

  static FlowEngine::Settings engine_settings(GstNeuflow *self) {
    GST_OBJECT_LOCK(self);
    const FlowEngine::Settings s{self->priv->settings.behaviour, self->priv->settings.stats_interval};
    GST_OBJECT_UNLOCK(self);
    return s;
  }

  Settings settings;  // under the object lock
  std::shared_ptr<const FlowModel> model;
  SrcPadDownstream downstream;
  FlowEngine engine;
};

G_DEFINE_TYPE(GstNeuflow, gst_neuflow, GST_TYPE_ELEMENT)

#define GST_NEUFLOW(obj) (reinterpret_cast<GstNeuflow *>(obj))

// The sizes the session takes (SessionLimits), so a frame it would refuse fails negotiation.
#define NEUFLOW_VIDEO_CAPS                                                                                  \
  "video/x-raw, format=(string){ RGB, BGR, RGBx, BGRx, xRGB, xBGR, RGBA, BGRA, GRAY8, I420, NV12, YUY2 }, " \
  "width=(int)[ 32, 16384 ], height=(int)[ 32, 16384 ], framerate=(fraction)[ 0/1, 2147483647/1 ]"
static_assert(SessionLimits::min_side == 32 && SessionLimits::max_side == 16384, "NEUFLOW_VIDEO_CAPS's sizes");

static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS(NEUFLOW_VIDEO_CAPS));
static GstStaticPadTemplate src_template =
    GST_STATIC_PAD_TEMPLATE("src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(NEUFLOW_VIDEO_CAPS));

static Settings gst_neuflow_copy_settings(GstNeuflow *self) {
  GST_OBJECT_LOCK(self);
  Settings s = self->priv->settings;
  GST_OBJECT_UNLOCK(self);
  return s;
}

// ---- pads ----------------------------------------------------------------------------------

static bool gst_neuflow_upstream_is_live(GstNeuflow *self) {
  GstQuery *query = gst_query_new_latency();
  gboolean live = FALSE;
  if (gst_pad_peer_query(self->sinkpad, query)) gst_query_parse_latency(query, &live, nullptr, nullptr);
  gst_query_unref(query);
  return live;
}

static GstFlowReturn gst_neuflow_sink_chain(GstPad * /*pad*/, GstObject *parent, GstBuffer *buffer) {
  auto *self = GST_NEUFLOW(parent);
  return self->priv->engine.chain(buffer, [self] { return gst_neuflow_upstream_is_live(self); });
}

static gboolean gst_neuflow_sink_event(GstPad *pad, GstObject *parent, GstEvent *event) {
  auto *self = GST_NEUFLOW(parent);
  FlowEngine &engine = self->priv->engine;
  switch (GST_EVENT_TYPE(event)) {
    case GST_EVENT_FLUSH_START: {
      engine.begin_flush();
      const gboolean ok = gst_pad_push_event(self->srcpad, event);  // unblocks a sink holding the push task
      engine.pause_for_flush();
      return ok;
    }
    case GST_EVENT_FLUSH_STOP:
      return engine.end_flush([self, event] { return gst_pad_push_event(self->srcpad, event) != FALSE; });
    default: break;
  }
  if (!GST_EVENT_IS_SERIALIZED(event)) return gst_pad_event_default(pad, parent, event);
  return engine.queue_event(event);
}

static gboolean gst_neuflow_sink_query(GstPad *pad, GstObject *parent, GstQuery *query) {
  auto *self = GST_NEUFLOW(parent);
  // Serialized queries (allocation, drain) must not overtake the frames queued before them.
  if (GST_QUERY_IS_SERIALIZED(query) && !self->priv->engine.drain()) return FALSE;
  return gst_pad_query_default(pad, parent, query);
}

static gboolean gst_neuflow_src_query(GstPad *pad, GstObject *parent, GstQuery *query) {
  auto *self = GST_NEUFLOW(parent);
  if (GST_QUERY_TYPE(query) != GST_QUERY_LATENCY) return gst_pad_query_default(pad, parent, query);
  if (!gst_pad_peer_query(self->sinkpad, query)) return FALSE;
  gboolean live = FALSE;
  GstClockTime min = 0, max = GST_CLOCK_TIME_NONE;
  gst_query_parse_latency(query, &live, &min, &max);
  // A frame waits at most for the one being computed, then for its own computation.
  const auto ours = static_cast<GstClockTime>(2 * self->priv->engine.announced_latency() * GST_SECOND);
  min += ours;
  if (GST_CLOCK_TIME_IS_VALID(max)) max += ours;
  gst_query_set_latency(query, live, min, max);
  return TRUE;
}

static gboolean gst_neuflow_src_activate_mode(GstPad * /*pad*/, GstObject *parent, GstPadMode mode, gboolean active) {
  auto *self = GST_NEUFLOW(parent);
  if (mode != GST_PAD_MODE_PUSH) return FALSE;
  if (active) return self->priv->engine.start();
  self->priv->engine.stop();
  return TRUE;
}

// ---- lifecycle -----------------------------------------------------------------------------

static GstStateChangeReturn gst_neuflow_change_state(GstElement *element, GstStateChange transition) {
  auto *self = GST_NEUFLOW(element);
  GstNeuflowPrivate &priv = *self->priv;
  switch (transition) {
    case GST_STATE_CHANGE_NULL_TO_READY: {
      const Settings s = gst_neuflow_copy_settings(self);
      if (s.model.empty()) {
        GST_ELEMENT_ERROR(self, RESOURCE, NOT_FOUND, ("no model given"),
                          ("set the 'model' property to a NeuFlow-V2 checkpoint (.pth)"));
        return GST_STATE_CHANGE_FAILURE;
      }
      try {
        priv.model = FlowModel::load_shared(s.model);
      } catch (const std::exception &e) {
        GST_ELEMENT_ERROR(self, RESOURCE, OPEN_READ, ("cannot load the model: %s", e.what()), (nullptr));
        return GST_STATE_CHANGE_FAILURE;
      }
      break;
    }
    case GST_STATE_CHANGE_READY_TO_PAUSED: {
      const Settings s = gst_neuflow_copy_settings(self);
      try {
        priv.engine.open(priv.model, s.session);
      } catch (const neuflow::model::BackendError &e) {
        GST_ELEMENT_ERROR(self, RESOURCE, FAILED, ("cannot run on the GPU: %s", e.what()),
                          ("backend=%s device=%d; `neuflow devices` lists the Vulkan devices",
                           std::string(neuflow::model::backend_name(s.session.backend)).c_str(), s.session.device));
        return GST_STATE_CHANGE_FAILURE;
      } catch (const std::exception &e) {
        GST_ELEMENT_ERROR(self, LIBRARY, SETTINGS, ("invalid settings: %s", e.what()), (nullptr));
        return GST_STATE_CHANGE_FAILURE;
      }
      if (const std::string warning = priv.engine.fallback_warning(); !warning.empty()) {
        GST_ELEMENT_WARNING(self, RESOURCE, FAILED, ("%s", warning.c_str()), (nullptr));
      }
      break;
    }
    default: break;
  }

  const GstStateChangeReturn ret = GST_ELEMENT_CLASS(gst_neuflow_parent_class)->change_state(element, transition);
  if (ret == GST_STATE_CHANGE_FAILURE) return ret;

  switch (transition) {
    case GST_STATE_CHANGE_PAUSED_TO_READY:  // pads are deactivated: the engine's tasks have stopped
      priv.engine.close();
      break;
    case GST_STATE_CHANGE_READY_TO_NULL: priv.model.reset(); break;
    default: break;
  }
  return ret;
}

// ---- properties ----------------------------------------------------------------------------

static void gst_neuflow_set_property(GObject *object, guint id, const GValue *value, GParamSpec *pspec) {
  auto *self = GST_NEUFLOW(object);
  GST_OBJECT_LOCK(self);
  Settings &s = self->priv->settings;
  // The param specs' ranges keep each value within int.
  const auto as_int = [value] { return static_cast<int>(g_value_get_uint(value)); };
  switch (id) {
    case PROP_MODEL: s.model = g_value_get_string(value) ? g_value_get_string(value) : ""; break;
    case PROP_ITERS_S16: s.session.iterations.s16 = as_int(); break;
    case PROP_ITERS_S8: s.session.iterations.s8 = as_int(); break;
    case PROP_MODEL_WIDTH: s.session.model_width = as_int(); break;
    case PROP_MODEL_HEIGHT: s.session.model_height = as_int(); break;
    case PROP_THREADS: s.session.threads = as_int(); break;
    case PROP_CHANNEL_ORDER: s.session.network_order = static_cast<ChannelOrder>(g_value_get_enum(value)); break;
    case PROP_BACKEND: s.session.backend = static_cast<Backend>(g_value_get_enum(value)); break;
    case PROP_DEVICE: s.session.device = g_value_get_int(value); break;
    case PROP_PRECISION: s.session.precision = static_cast<Precision>(g_value_get_enum(value)); break;
    case PROP_MAX_MEMORY: s.session.max_memory_mb = as_int(); break;
    case PROP_BEHAVIOUR: s.behaviour = static_cast<Behaviour>(g_value_get_enum(value)); break;
    case PROP_STATS_INTERVAL: s.stats_interval = g_value_get_uint(value); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_get_property(GObject *object, guint id, GValue *value, GParamSpec *pspec) {
  auto *self = GST_NEUFLOW(object);
  const FlowEngine &engine = self->priv->engine;
  if (id == PROP_RUNNING_ON) {
    g_value_set_string(value, engine.running_on().c_str());
    return;
  }
  if (id >= PROP_FRAMES_IN) {
    const neuflow::gst::FlowStats s = engine.stats();
    switch (id) {
      case PROP_FRAMES_IN: g_value_set_uint64(value, s.frames_in()); break;
      case PROP_FRAMES_PROCESSED: g_value_set_uint64(value, s.processed()); break;
      case PROP_FLOWS: g_value_set_uint64(value, s.flows()); break;
      case PROP_FRAMES_DROPPED: g_value_set_uint64(value, s.frames_dropped()); break;
      case PROP_MEAN_LATENCY: g_value_set_double(value, s.mean_latency_ms()); break;
      case PROP_PROCESSING_RATE: g_value_set_double(value, s.processing_rate(std::chrono::steady_clock::now())); break;
      default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec); break;
    }
    return;
  }
  const Settings s = gst_neuflow_copy_settings(self);
  switch (id) {
    case PROP_MODEL: g_value_set_string(value, s.model.c_str()); break;
    case PROP_ITERS_S16: g_value_set_uint(value, static_cast<guint>(s.session.iterations.s16)); break;
    case PROP_ITERS_S8: g_value_set_uint(value, static_cast<guint>(s.session.iterations.s8)); break;
    case PROP_MODEL_WIDTH: g_value_set_uint(value, static_cast<guint>(s.session.model_width)); break;
    case PROP_MODEL_HEIGHT: g_value_set_uint(value, static_cast<guint>(s.session.model_height)); break;
    case PROP_THREADS: g_value_set_uint(value, static_cast<guint>(s.session.threads)); break;
    case PROP_CHANNEL_ORDER: g_value_set_enum(value, static_cast<gint>(s.session.network_order)); break;
    case PROP_BACKEND: g_value_set_enum(value, static_cast<gint>(s.session.backend)); break;
    case PROP_DEVICE: g_value_set_int(value, s.session.device); break;
    case PROP_PRECISION: g_value_set_enum(value, static_cast<gint>(s.session.precision)); break;
    case PROP_MAX_MEMORY: g_value_set_uint(value, static_cast<guint>(s.session.max_memory_mb)); break;
    case PROP_BEHAVIOUR: g_value_set_enum(value, static_cast<gint>(s.behaviour)); break;
    case PROP_STATS_INTERVAL: g_value_set_uint(value, s.stats_interval); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, id, pspec); break;
  }
}

static void gst_neuflow_finalize(GObject *object) {
  auto *self = GST_NEUFLOW(object);
  delete self->priv;  // the engine stops and joins its tasks first
  G_OBJECT_CLASS(gst_neuflow_parent_class)->finalize(object);
}

static void gst_neuflow_install_properties(GObjectClass *gobject_class) {
  constexpr auto rw = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);
  constexpr auto ro = static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS);
  // The model is loaded when the element leaves NULL, so it can only change in NULL.
  constexpr auto rw_null = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS);
  constexpr auto rw_playing =
      static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING);
  const auto install = [gobject_class](guint id, GParamSpec *spec) {
    g_object_class_install_property(gobject_class, id, spec);
  };
  // The session's settings: names and help from option_docs, shared with the command and neuflowd.
  const auto uint_setting = [&](guint id, const neuflow::model::OptionDoc &doc, const char *nick, int max, int def) {
    install(id, g_param_spec_uint(doc.name.data(), nick, doc.help.data(), 0, static_cast<guint>(max),
                                  static_cast<guint>(def), rw));
  };
  const auto enum_setting = [&](guint id, const neuflow::model::OptionDoc &doc, const char *nick, GType type, int def) {
    install(id, g_param_spec_enum(doc.name.data(), nick, doc.help.data(), type, def, rw));
  };
  const auto &d = DEFAULT_PROP_SESSION;
  install(PROP_MODEL, g_param_spec_string("model", "Model",
                                          "NeuFlow-V2 checkpoint (.pth), e.g. neuflow_mixed.pth; loaded once when "
                                          "the element leaves NULL and shared with other elements using the same file",
                                          nullptr, rw_null));
  uint_setting(PROP_ITERS_S16, docs::iters_s16, "Iters 1/16", SessionLimits::max_iterations_s16, d.iterations.s16);
  uint_setting(PROP_ITERS_S8, docs::iters_s8, "Iterations at 1/8", SessionLimits::max_iterations_s8, d.iterations.s8);
  uint_setting(PROP_MODEL_WIDTH, docs::model_width, "Model width", SessionLimits::max_side, d.model_width);
  uint_setting(PROP_MODEL_HEIGHT, docs::model_height, "Model height", SessionLimits::max_side, d.model_height);
  uint_setting(PROP_THREADS, docs::threads, "Threads", SessionLimits::max_threads, d.threads);
  enum_setting(PROP_CHANNEL_ORDER, docs::channel_order, "Channel order", gst_neuflow_channel_order_get_type(),
               static_cast<gint>(d.network_order));
  enum_setting(PROP_BACKEND, docs::backend, "Backend", gst_neuflow_backend_get_type(), static_cast<gint>(d.backend));
  install(PROP_DEVICE, g_param_spec_int(docs::device.name.data(), "Device", docs::device.help.data(), -1,
                                        SessionLimits::max_device, d.device, rw));
  enum_setting(PROP_PRECISION, docs::precision, "Precision", gst_neuflow_precision_get_type(),
               static_cast<gint>(d.precision));
  uint_setting(PROP_MAX_MEMORY, docs::max_memory, "Max memory", SessionLimits::max_memory_mb, d.max_memory_mb);
  install(PROP_RUNNING_ON,
          g_param_spec_string("running-on", "Running on",
                              "Where the network runs once PAUSED: cpu or vulkan device N (name)", "", ro));
  enum_setting(PROP_BEHAVIOUR, docs::behaviour, "Behaviour", gst_neuflow_behaviour_get_type(),
               static_cast<gint>(DEFAULT_PROP_BEHAVIOUR));
  install(PROP_STATS_INTERVAL,
          g_param_spec_uint("stats-interval", "Stats interval",
                            "Milliseconds between 'neuflow-stats' element messages carrying the counters (0: none)", 0,
                            G_MAXUINT, DEFAULT_PROP_STATS_INTERVAL, rw_playing));
  // The counters, read-only.
  install(PROP_FRAMES_IN, g_param_spec_uint64("frames-in", "Frames in", "Frames received", 0, G_MAXUINT64, 0, ro));
  install(PROP_FRAMES_PROCESSED,
          g_param_spec_uint64("frames-processed", "Frames processed",
                              "Frames computed, each stream's first (no flow yet) included", 0, G_MAXUINT64, 0, ro));
  install(PROP_FLOWS, g_param_spec_uint64("flows", "Flows",
                                          "Frames that left with a flow (frames-processed less the first frame of "
                                          "each stream, of each flush and of each size change)",
                                          0, G_MAXUINT64, 0, ro));
  install(PROP_FRAMES_DROPPED,
          g_param_spec_uint64("frames-dropped", "Frames dropped", "Frames dropped to hold real-time (live behaviour)",
                              0, G_MAXUINT64, 0, ro));
  install(PROP_MEAN_LATENCY, g_param_spec_double("mean-latency", "Mean latency",
                                                 "Mean inference time per flow, milliseconds", 0, G_MAXDOUBLE, 0, ro));
  install(PROP_PROCESSING_RATE, g_param_spec_double("processing-rate", "Processing rate",
                                                    "Frames leaving the element per second", 0, G_MAXDOUBLE, 0, ro));
}

static void gst_neuflow_class_init(GstNeuflowClass *klass) {
  auto *gobject_class = G_OBJECT_CLASS(klass);
  auto *element_class = GST_ELEMENT_CLASS(klass);
  gobject_class->set_property = gst_neuflow_set_property;
  gobject_class->get_property = gst_neuflow_get_property;
  gobject_class->finalize = gst_neuflow_finalize;
  element_class->change_state = gst_neuflow_change_state;
  gst_neuflow_install_properties(gobject_class);

  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);
  gst_element_class_set_static_metadata(element_class, "NeuFlow-V2 optical flow", "Filter/Analyzer/Video",
                                        "Computes optical flow between video frames and attaches it as metadata",
                                        "neuflow");
  gst_element_class_add_static_metadata(element_class, GST_ELEMENT_METADATA_DOC_URI, NEUFLOW_DOC_URI);
  for (GType type : {gst_neuflow_channel_order_get_type(), gst_neuflow_behaviour_get_type(),
                     gst_neuflow_backend_get_type(), gst_neuflow_precision_get_type()}) {
    gst_type_mark_as_plugin_api(type, static_cast<GstPluginAPIFlags>(0));
  }
  GST_DEBUG_CATEGORY_INIT(gst_neuflow_debug, "neuflow", 0, "NeuFlow-V2 optical flow element");
}

static void gst_neuflow_init(GstNeuflow *self) {
  self->sinkpad = gst_pad_new_from_static_template(&sink_template, "sink");
  gst_pad_set_chain_function(self->sinkpad, gst_neuflow_sink_chain);
  gst_pad_set_event_function(self->sinkpad, gst_neuflow_sink_event);
  gst_pad_set_query_function(self->sinkpad, gst_neuflow_sink_query);
  GST_PAD_SET_PROXY_CAPS(self->sinkpad);
  gst_element_add_pad(GST_ELEMENT(self), self->sinkpad);

  self->srcpad = gst_pad_new_from_static_template(&src_template, "src");
  gst_pad_set_query_function(self->srcpad, gst_neuflow_src_query);
  gst_pad_set_activatemode_function(self->srcpad, gst_neuflow_src_activate_mode);
  GST_PAD_SET_PROXY_CAPS(self->srcpad);
  gst_element_add_pad(GST_ELEMENT(self), self->srcpad);

  self->priv = new GstNeuflowPrivate(self);  // after the pads: the engine pushes through srcpad
}

GST_ELEMENT_REGISTER_DEFINE(neuflow, "neuflow", GST_RANK_NONE, gst_neuflow_get_type());
