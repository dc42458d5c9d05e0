#include "gstneuflowflowsink.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_flow_sink_debug);
#define GST_CAT_DEFAULT gst_neuflow_flow_sink_debug

enum {
  PROP_0,
  PROP_FLOWS_WRITTEN,
  PROP_BYTES_WRITTEN,
  PROP_BUFFERS_SKIPPED,
};

struct GstNeuflowFlowSinkPrivate {
  // Under the object lock: the application may read them from any thread.
  guint64 flows_written;
  guint64 bytes_written;
  guint64 buffers_skipped;
  gboolean warned_no_flow;  // the no-flow warning was posted this run
};

// Buffers without flow are normal at the start of a stream and after a flush or a size change
// (one each); this many with no flow at all means nothing upstream computes flow.
constexpr guint64 kBuffersBeforeNoFlowWarning = 3;

G_DEFINE_ABSTRACT_TYPE_WITH_CODE(GstNeuflowFlowSink, gst_neuflow_flow_sink, GST_TYPE_BASE_SINK,
                                 G_ADD_PRIVATE(GstNeuflowFlowSink)
                                     GST_DEBUG_CATEGORY_INIT(gst_neuflow_flow_sink_debug, "neuflowflowsink", 0,
                                                             "Base of the NeuFlow flow sinks"))

// Any raw video (any format, any memory): only the flow meta is read, never the pixels.
static GstStaticPadTemplate sink_template =
    GST_STATIC_PAD_TEMPLATE("sink", GST_PAD_SINK, GST_PAD_ALWAYS, GST_STATIC_CAPS("video/x-raw(ANY)"));

static GstNeuflowFlowSinkPrivate *gst_neuflow_flow_sink_private(GstNeuflowFlowSink *self) {
  return static_cast<GstNeuflowFlowSinkPrivate *>(gst_neuflow_flow_sink_get_instance_private(self));
}

static void gst_neuflow_flow_sink_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec) {
  GstNeuflowFlowSink *self = GST_NEUFLOW_FLOW_SINK(object);
  GstNeuflowFlowSinkPrivate *priv = gst_neuflow_flow_sink_private(self);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_FLOWS_WRITTEN: g_value_set_uint64(value, priv->flows_written); break;
    case PROP_BYTES_WRITTEN: g_value_set_uint64(value, priv->bytes_written); break;
    case PROP_BUFFERS_SKIPPED: g_value_set_uint64(value, priv->buffers_skipped); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

// The subclass starts here rather than in GstBaseSink::start: when start() fails, GstBaseSink
// posts a second, generic error ("state change failed and some element failed to post a
// proper error message") after the subclass's own, and users saw both.
static GstStateChangeReturn gst_neuflow_flow_sink_change_state(GstElement *element, GstStateChange transition) {
  GstNeuflowFlowSink *self = GST_NEUFLOW_FLOW_SINK(element);
  GstNeuflowFlowSinkClass *klass = GST_NEUFLOW_FLOW_SINK_GET_CLASS(self);
  if (transition == GST_STATE_CHANGE_NULL_TO_READY) {
    GstNeuflowFlowSinkPrivate *priv = gst_neuflow_flow_sink_private(self);
    GST_OBJECT_LOCK(self);
    priv->flows_written = 0;
    priv->bytes_written = 0;
    priv->buffers_skipped = 0;
    priv->warned_no_flow = FALSE;
    GST_OBJECT_UNLOCK(self);
    if (!klass->start_writing(self)) {
      klass->stop_writing(self);
      return GST_STATE_CHANGE_FAILURE;  // start_writing posted the error
    }
  }
  const GstStateChangeReturn ret =
      GST_ELEMENT_CLASS(gst_neuflow_flow_sink_parent_class)->change_state(element, transition);
  if (ret == GST_STATE_CHANGE_FAILURE && transition == GST_STATE_CHANGE_NULL_TO_READY) klass->stop_writing(self);
  return ret;
}

static gboolean gst_neuflow_flow_sink_stop(GstBaseSink *sink) {
  GstNeuflowFlowSink *self = GST_NEUFLOW_FLOW_SINK(sink);
  GstNeuflowFlowSinkPrivate *priv = gst_neuflow_flow_sink_private(self);
  GstNeuflowFlowSinkClass *klass = GST_NEUFLOW_FLOW_SINK_GET_CLASS(self);
  GST_OBJECT_LOCK(self);
  GST_INFO_OBJECT(self, "wrote %" G_GUINT64_FORMAT " %s, skipped %" G_GUINT64_FORMAT " buffers without flow",
                  priv->flows_written, klass->written_noun, priv->buffers_skipped);
  GST_OBJECT_UNLOCK(self);
  klass->stop_writing(self);
  return TRUE;
}

static GstFlowReturn gst_neuflow_flow_sink_render(GstBaseSink *sink, GstBuffer *buffer) {
  GstNeuflowFlowSink *self = GST_NEUFLOW_FLOW_SINK(sink);
  GstNeuflowFlowSinkPrivate *priv = gst_neuflow_flow_sink_private(self);
  const NeuflowFlowMeta *meta = neuflow_buffer_get_flow_meta(buffer);
  if (!meta || meta->width == 0 || meta->height == 0) {
    GST_OBJECT_LOCK(self);
    ++priv->buffers_skipped;
    const bool warn =
        !priv->warned_no_flow && priv->flows_written == 0 && priv->buffers_skipped == kBuffersBeforeNoFlowWarning;
    if (warn) priv->warned_no_flow = TRUE;
    GST_OBJECT_UNLOCK(self);
    GST_LOG_OBJECT(self, "buffer %" GST_TIME_FORMAT " has no flow: skipped", GST_TIME_ARGS(GST_BUFFER_PTS(buffer)));
    if (warn) {
      const gchar *factory = GST_OBJECT_NAME(gst_element_get_factory(GST_ELEMENT(self)));
      GST_ELEMENT_WARNING(self, STREAM, FORMAT,
                          ("Nothing to write: the first %" G_GUINT64_FORMAT
                           " buffers carry no optical flow. Is a neuflow element upstream? "
                           "(… ! neuflow model=neuflow_mixed.pth ! %s …)",
                           kBuffersBeforeNoFlowWarning, factory),
                          ("%s writes the NeuflowFlowMeta the neuflow element attaches; buffers without it are "
                           "skipped (see buffers-skipped)",
                           factory));
    }
    return GST_FLOW_OK;
  }

  // The meta is produced by other code: its vectors must be as many as its grid says.
  const gsize have = meta->data ? g_bytes_get_size(meta->data) : 0;
  const guint64 need = static_cast<guint64>(meta->width) * meta->height * 2 * sizeof(gfloat);
  if (have < need) {
    GST_ELEMENT_ERROR(
        self, STREAM, FORMAT,
        ("Flow metadata of a %ux%u grid holds %" G_GSIZE_FORMAT " bytes of vectors, expected %" G_GUINT64_FORMAT ".",
         meta->width, meta->height, have, need),
        ("buffer %" GST_TIME_FORMAT, GST_TIME_ARGS(GST_BUFFER_PTS(buffer))));
    return GST_FLOW_ERROR;
  }

  guint64 bytes = 0;
  const GstFlowReturn ret = GST_NEUFLOW_FLOW_SINK_GET_CLASS(self)->write_flow(self, buffer, meta, &bytes);
  if (ret == GST_FLOW_OK) {
    GST_OBJECT_LOCK(self);
    ++priv->flows_written;
    priv->bytes_written += bytes;
    GST_OBJECT_UNLOCK(self);
  }
  return ret;
}

static void gst_neuflow_flow_sink_class_init(GstNeuflowFlowSinkClass *klass) {
  GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
  GstBaseSinkClass *sink_class = GST_BASE_SINK_CLASS(klass);

  gobject_class->get_property = gst_neuflow_flow_sink_get_property;

  constexpr auto ro = static_cast<GParamFlags>(G_PARAM_READABLE | G_PARAM_STATIC_STRINGS);
  g_object_class_install_property(
      gobject_class, PROP_FLOWS_WRITTEN,
      g_param_spec_uint64("flows-written", "Flows written",
                          "Flows written out (files, or flows published into the ring) since the element started", 0,
                          G_MAXUINT64, 0, ro));
  g_object_class_install_property(
      gobject_class, PROP_BYTES_WRITTEN,
      g_param_spec_uint64("bytes-written", "Bytes written",
                          "Bytes of flow written out (the flow files' sizes, or the vectors published into the "
                          "ring) since the element started",
                          0, G_MAXUINT64, 0, ro));
  g_object_class_install_property(
      gobject_class, PROP_BUFFERS_SKIPPED,
      g_param_spec_uint64("buffers-skipped", "Buffers skipped",
                          "Buffers without flow (no NeuflowFlowMeta) since the element started", 0, G_MAXUINT64, 0,
                          ro));

  gst_element_class_add_static_pad_template(element_class, &sink_template);

  element_class->change_state = GST_DEBUG_FUNCPTR(gst_neuflow_flow_sink_change_state);
  sink_class->stop = GST_DEBUG_FUNCPTR(gst_neuflow_flow_sink_stop);
  sink_class->render = GST_DEBUG_FUNCPTR(gst_neuflow_flow_sink_render);
  klass->written_noun = "flows";
}

static void gst_neuflow_flow_sink_init(GstNeuflowFlowSink *self) {
  GstNeuflowFlowSinkPrivate *priv = gst_neuflow_flow_sink_private(self);
  priv->flows_written = 0;
  priv->bytes_written = 0;
  priv->buffers_skipped = 0;
  // A writer of files and memory, like filesink: each flow goes out as soon as it exists.
  gst_base_sink_set_sync(GST_BASE_SINK(self), FALSE);
}
