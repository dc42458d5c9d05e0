#pragma once
// Attaching a computed flow to the frame it ends at, as the NeuflowFlowMeta that the sinks,
// neuflowviz and applications read.
#include <gst/gst.h>

#include "neuflow/flow/flow_field.hpp"
#include "neuflow/model/session_settings.hpp"

namespace neuflow::gst {

// The two frames a flow goes between.
struct FlowEnds {
  GstClockTime from_pts = GST_CLOCK_TIME_NONE;
  GstClockTime to_pts = GST_CLOCK_TIME_NONE;
  guint64 from_frame = 0;
  guint64 to_frame = 0;
};

// `buffer` made writable with the flow attached; `options` are the session's (its model size
// and iterations are recorded with the flow).
GstBuffer* attach_flow(GstBuffer* buffer, const flow::FlowField& flow, const FlowEnds& ends,
                       const model::SessionOptions& options, double inference_seconds);

}  // namespace neuflow::gst
