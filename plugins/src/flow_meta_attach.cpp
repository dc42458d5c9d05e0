#include "flow_meta_attach.hpp"

#include "neuflow/gst/flow_meta.h"

namespace neuflow::gst {

GstBuffer* attach_flow(GstBuffer* buffer, const flow::FlowField& flow, const FlowEnds& ends,
                       const model::SessionOptions& options, double inference_seconds) {
  buffer = gst_buffer_make_writable(buffer);
  GBytes* bytes = g_bytes_new(flow.uv.data(), flow.uv.size() * sizeof(float));
  NeuflowFlowMeta* meta =
      neuflow_buffer_add_flow_meta(buffer, static_cast<guint>(flow.width), static_cast<guint>(flow.height), bytes);
  g_bytes_unref(bytes);
  meta->from_pts = ends.from_pts;
  meta->to_pts = ends.to_pts;
  meta->from_frame = ends.from_frame;
  meta->to_frame = ends.to_frame;
  const model::ModelSize size = model::model_size_for(flow.width, flow.height, options);
  meta->model_width = static_cast<guint>(size.width);
  meta->model_height = static_cast<guint>(size.height);
  meta->iters_s16 = static_cast<guint>(options.iterations.s16);
  meta->iters_s8 = static_cast<guint>(options.iterations.s8);
  meta->inference_time = static_cast<GstClockTime>(inference_seconds * GST_SECOND);
  return buffer;
}

}  // namespace neuflow::gst
