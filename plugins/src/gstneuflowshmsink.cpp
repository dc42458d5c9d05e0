/**
 * SECTION:element-neuflowshmsink
 * @title: neuflowshmsink
 *
 * Publishes the optical flow attached to each video frame (#NeuflowFlowMeta, from the
 * `neuflow` element) into a POSIX shared-memory ring holding the latest
 * #neuflowshmsink:slots flows with their frame numbers and timestamps, for other processes
 * on the machine to read without copying files around. The layout (versioned, little-endian,
 * one seqlock per slot so that a reader never sees a torn flow and never blocks the writer)
 * and a header-only C++ reader are in `neuflow/flow_ring.hpp`; docs/shm-ring.md describes
 * them and a Python reader.
 *
 * The segment is created with #neuflowshmsink:shm-mode (0640 by default: readers run as the
 * pipeline's user or in its group; neuflowd's systemd units run with the fixed group
 * `neuflow` for that, which reader accounts join) when the element starts, as a placeholder that readers see as "not ready", and sized for
 * the flow grid at the first flow. When the grid size changes the writer creates a new
 * segment under the same name with the next `generation` and marks the old one closed, which
 * tells readers to open the name again. When the element stops it marks the segment closed
 * and unlinks the name; readers that have it mapped keep reading the last flows.
 *
 * A segment left under the name by a writer that died is replaced; one in use by another
 * running writer (it holds a lock on it) makes the element fail to start.
 *
 * Buffers without flow are skipped and counted in #neuflowshmsink:buffers-skipped. The sink
 * does not synchronize to the clock by default (sync=false): consumers want each flow as
 * soon as it exists.
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 v4l2src ! videoconvert ! neuflow model=neuflow_mixed.pth ! neuflowshmsink shm-name=/neuflow-front
 * ]|
 */
#include <gst/gst.h>

#include <exception>
#include <memory>
#include <span>
#include <string>

#include "elements.hpp"
#include "flow_ring_writer.hpp"
#include "gstneuflowflowsink.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_shm_sink_debug);
#define GST_CAT_DEFAULT gst_neuflow_shm_sink_debug

enum {
  PROP_0,
  PROP_SHM_NAME,
  PROP_SLOTS,
  PROP_SHM_MODE,
};

#define DEFAULT_PROP_SLOTS 4
#define MAX_PROP_SLOTS 64
#define DEFAULT_PROP_SHM_MODE 0640

struct GstNeuflowShmSink {
  GstNeuflowFlowSink parent;

  // Properties, under the object lock.
  gchar *shm_name;
  guint slots;
  guint shm_mode;

  // Generations continue across restarts of this element, so that a reader that saw the
  // segment of a previous run can tell the new one apart.
  guint64 next_generation;

  // From start() to stop(); render() runs only in between (GstBaseSink guarantees it).
  neuflow::gst::FlowRingWriter *writer;
};

struct GstNeuflowShmSinkClass {
  GstNeuflowFlowSinkClass parent_class;
};

#define GST_NEUFLOW_SHM_SINK(obj) (reinterpret_cast<GstNeuflowShmSink *>(obj))

G_DEFINE_TYPE_WITH_CODE(GstNeuflowShmSink, gst_neuflow_shm_sink, GST_TYPE_NEUFLOW_FLOW_SINK,
                        GST_DEBUG_CATEGORY_INIT(gst_neuflow_shm_sink_debug, "neuflowshmsink", 0,
                                                "NeuFlow optical flow shared-memory ring writer"))

static void gst_neuflow_shm_sink_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec) {
  GstNeuflowShmSink *self = GST_NEUFLOW_SHM_SINK(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_SHM_NAME:
      g_free(self->shm_name);
      self->shm_name = g_value_dup_string(value);
      break;
    case PROP_SLOTS: self->slots = g_value_get_uint(value); break;
    case PROP_SHM_MODE: self->shm_mode = g_value_get_uint(value); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_shm_sink_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec) {
  GstNeuflowShmSink *self = GST_NEUFLOW_SHM_SINK(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_SHM_NAME: g_value_set_string(value, self->shm_name); break;
    case PROP_SLOTS: g_value_set_uint(value, self->slots); break;
    case PROP_SHM_MODE: g_value_set_uint(value, self->shm_mode); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_shm_sink_close(GstNeuflowShmSink *self) {
  if (!self->writer) return;
  self->next_generation = self->writer->generation() + 1;
  delete self->writer;
  self->writer = nullptr;
}

static void gst_neuflow_shm_sink_finalize(GObject *object) {
  GstNeuflowShmSink *self = GST_NEUFLOW_SHM_SINK(object);
  gst_neuflow_shm_sink_close(self);
  g_free(self->shm_name);
  G_OBJECT_CLASS(gst_neuflow_shm_sink_parent_class)->finalize(object);
}

// Validates the name and takes the segment over, so that a typo, a clash with another
// writer or a permission problem stops the pipeline at once rather than at the first flow.
static gboolean gst_neuflow_shm_sink_start_writing(GstNeuflowFlowSink *sink) {
  GstNeuflowShmSink *self = GST_NEUFLOW_SHM_SINK(sink);

  GST_OBJECT_LOCK(self);
  g_autofree gchar *name = g_strdup(self->shm_name);
  const guint slots = self->slots;
  const auto mode = static_cast<mode_t>(self->shm_mode);
  GST_OBJECT_UNLOCK(self);

  if (!name || !*name) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("No shared-memory name set for the flow ring."),
                      ("set the shm-name property, e.g. shm-name=/neuflow-front"));
    return FALSE;
  }
  if (auto problem = neuflow::gst::check_flow_ring_name(name)) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS, ("Invalid shm-name \"%s\": %s.", name, problem->c_str()), (nullptr));
    return FALSE;
  }

  if (auto problem = neuflow::gst::check_flow_ring_mode(mode)) {
    GST_ELEMENT_ERROR(self, RESOURCE, SETTINGS,
                      ("Invalid shm-mode %04o: %s.", static_cast<unsigned>(mode), problem->c_str()), (nullptr));
    return FALSE;
  }

  gst_neuflow_shm_sink_close(self);
  try {
    self->writer = new neuflow::gst::FlowRingWriter(name, slots, self->next_generation, mode);
  } catch (const std::exception &e) {
    GST_ELEMENT_ERROR(self, RESOURCE, OPEN_WRITE, ("Could not create the shared-memory flow ring: %s.", e.what()),
                      (nullptr));
    return FALSE;
  }
  GST_INFO_OBJECT(self, "flow ring %s with %u slots, mode %04o, generation %" G_GUINT64_FORMAT, name, slots,
                  static_cast<unsigned>(mode), self->writer->generation());
  return TRUE;
}

static void gst_neuflow_shm_sink_stop_writing(GstNeuflowFlowSink *sink) {
  gst_neuflow_shm_sink_close(GST_NEUFLOW_SHM_SINK(sink));
}

static GstFlowReturn gst_neuflow_shm_sink_write_flow(GstNeuflowFlowSink *sink, GstBuffer * /*buffer*/,
                                                     const NeuflowFlowMeta *meta, guint64 *bytes) {
  GstNeuflowShmSink *self = GST_NEUFLOW_SHM_SINK(sink);
  const std::size_t values = static_cast<std::size_t>(meta->width) * meta->height * 2;

  neuflow::gst::FlowRecord record;
  record.from_frame = meta->from_frame;
  record.to_frame = meta->to_frame;
  record.from_pts_ns = meta->from_pts;  // GST_CLOCK_TIME_NONE is the ring's "unknown" too
  record.to_pts_ns = meta->to_pts;
  record.inference_ns = GST_CLOCK_TIME_IS_VALID(meta->inference_time) ? meta->inference_time : 0;
  record.frame_width = meta->frame_width;
  record.frame_height = meta->frame_height;
  record.model_width = meta->model_width;
  record.model_height = meta->model_height;
  record.iters_s16 = meta->iters_s16;
  record.iters_s8 = meta->iters_s8;
  const std::span<const float> uv(neuflow_flow_meta_get_vectors(meta), values);

  const std::uint64_t generation_before = self->writer->generation();
  try {
    self->writer->publish(meta->width, meta->height, record, uv);
  } catch (const std::exception &e) {
    GST_ELEMENT_ERROR(self, RESOURCE, WRITE, ("Could not publish the flow to shared memory: %s.", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
  if (self->writer->generation() != generation_before) {
    GST_INFO_OBJECT(self, "flow ring %s is now %ux%u, generation %" G_GUINT64_FORMAT, self->writer->name().c_str(),
                    meta->width, meta->height, self->writer->generation());
  }
  *bytes = values * sizeof(float);
  return GST_FLOW_OK;
}

static void gst_neuflow_shm_sink_class_init(GstNeuflowShmSinkClass *klass) {
  GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
  GstNeuflowFlowSinkClass *flow_sink_class = GST_NEUFLOW_FLOW_SINK_CLASS(klass);

  gobject_class->set_property = gst_neuflow_shm_sink_set_property;
  gobject_class->get_property = gst_neuflow_shm_sink_get_property;
  gobject_class->finalize = gst_neuflow_shm_sink_finalize;

  constexpr auto rw_ready =
      static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_READY);

  g_object_class_install_property(
      gobject_class, PROP_SHM_NAME,
      g_param_spec_string("shm-name", "Shared-memory name",
                          "Name of the POSIX shared-memory segment (required): a '/' followed by up to 255 "
                          "characters without another '/', e.g. /neuflow-front (on Linux /dev/shm/neuflow-front). "
                          "Created with shm-mode when the element starts, unlinked when it stops",
                          nullptr, rw_ready));
  g_object_class_install_property(
      gobject_class, PROP_SLOTS,
      g_param_spec_uint("slots", "Slots",
                        "Number of flows the ring holds: readers can still read a flow until this many newer ones "
                        "have been published",
                        1, MAX_PROP_SLOTS, DEFAULT_PROP_SLOTS, rw_ready));
  g_object_class_install_property(
      gobject_class, PROP_SHM_MODE,
      g_param_spec_uint("shm-mode", "Shared-memory mode",
                        "Permissions of the segment, set exactly whatever the umask (write it in octal: shm-mode=0644; "
                        "gst-launch reads a leading 0 as octal). The default 0640 lets the owner's group read: run "
                        "readers as that user or in that group. Read and write bits only, the owner's included. "
                        "gst-inspect-1.0 prints the values in decimal: 416 is 0640, 384 is 0600, 438 is 0666",
                        0600, 0666, DEFAULT_PROP_SHM_MODE, rw_ready));

  gst_element_class_set_static_metadata(
      element_class, "NeuFlow optical flow shared-memory sink", "Sink/Video/Analyzer",
      "Publishes the optical flow attached to video frames (NeuflowFlowMeta) into "
      "a POSIX shared-memory ring of the latest flows, for readers in other processes",
      "neuflow");
  gst_element_class_add_static_metadata(element_class, GST_ELEMENT_METADATA_DOC_URI, NEUFLOW_DOC_URI);
  flow_sink_class->start_writing = GST_DEBUG_FUNCPTR(gst_neuflow_shm_sink_start_writing);
  flow_sink_class->write_flow = GST_DEBUG_FUNCPTR(gst_neuflow_shm_sink_write_flow);
  flow_sink_class->stop_writing = GST_DEBUG_FUNCPTR(gst_neuflow_shm_sink_stop_writing);
  flow_sink_class->written_noun = "flows into the ring";
}

static void gst_neuflow_shm_sink_init(GstNeuflowShmSink *self) {
  self->shm_name = nullptr;
  self->slots = DEFAULT_PROP_SLOTS;
  self->shm_mode = DEFAULT_PROP_SHM_MODE;
  self->next_generation = 0;
  self->writer = nullptr;
}

GST_ELEMENT_REGISTER_DEFINE(neuflowshmsink, "neuflowshmsink", GST_RANK_NONE, gst_neuflow_shm_sink_get_type());
