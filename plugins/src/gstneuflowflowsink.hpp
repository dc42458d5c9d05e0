#pragma once
// GstNeuflowFlowSink: the abstract base of the sinks that write out the flow attached to
// video frames (neuflowsink: files; neuflowshmsink: a shared-memory ring). It owns what they
// share: the caps (any raw video: only the NeuflowFlowMeta is read), no clock sync by
// default, skipping and counting buffers without flow, checking that a meta holds as many
// vectors as its grid says, and the flows-written / buffers-skipped counters, reset at start
// and logged at stop, and bytes-written. A subclass implements the three virtual methods below.
#include <gst/base/gstbasesink.h>
#include <gst/gst.h>

#include "neuflow/gst/flow_meta.h"

G_BEGIN_DECLS

#define GST_TYPE_NEUFLOW_FLOW_SINK (gst_neuflow_flow_sink_get_type())
G_DECLARE_DERIVABLE_TYPE(GstNeuflowFlowSink, gst_neuflow_flow_sink, GST, NEUFLOW_FLOW_SINK, GstBaseSink)

struct _GstNeuflowFlowSinkClass {
  GstBaseSinkClass parent_class;

  // Prepares to write (settings checked, outputs opened) when the element goes from NULL to
  // READY, after the counters are reset; posts an element error and returns FALSE when it
  // cannot (the only error the application then sees).
  gboolean (*start_writing)(GstNeuflowFlowSink *sink);
  // Writes one flow whose meta holds width × height × 2 floats and sets `bytes` to what that
  // put out (the file's size, the vectors published); on failure posts an element error and
  // returns GST_FLOW_ERROR. Counted as written when it returns GST_FLOW_OK.
  GstFlowReturn (*write_flow)(GstNeuflowFlowSink *sink, GstBuffer *buffer, const NeuflowFlowMeta *meta, guint64 *bytes);
  // Releases what start_writing opened; may be called without a start_writing before it.
  void (*stop_writing)(GstNeuflowFlowSink *sink);
  // What the subclass writes, for the log: "flow files", "flows into the ring".
  const gchar *written_noun;
};

G_END_DECLS
