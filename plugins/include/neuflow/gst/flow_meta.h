/* GstNeuflowFlowMeta: the optical flow that ends at the video frame it is attached to.
 *
 * Attached by the `neuflow` element to each frame it has computed flow for. The flow points
 * from an earlier frame (from_pts) to this frame (to_pts); after dropped frames in live mode
 * the two are not consecutive, so consumers must use both timestamps, not assume a step.
 *
 * The field is a grid of width × height cells covering the whole frame it rides on
 * (frame_width × frame_height pixels): cell (x, y) holds (u, v) as two interleaved float32,
 * in pixels of that grid, u to the right and v downwards. A consumer drawing on a frame of
 * another size scales positions and vectors by frame_width / width and frame_height / height.
 * Scaling transforms (videoscale) keep the grid and update frame_width / frame_height.
 *
 * The data is shared (reference-counted) between copies of the meta and never modified.
 */
#ifndef NEUFLOW_GST_FLOW_META_H
#define NEUFLOW_GST_FLOW_META_H

#include <gst/gst.h>

G_BEGIN_DECLS

#define NEUFLOW_FLOW_META_API_TYPE (neuflow_flow_meta_api_get_type())
#define NEUFLOW_FLOW_META_INFO (neuflow_flow_meta_get_info())

typedef struct {
  GstMeta meta;

  guint width; /* flow grid size */
  guint height;
  GBytes *data; /* width * height * 2 float32: u, v interleaved, row-major */

  guint frame_width; /* the frame the grid covers */
  guint frame_height;

  GstClockTime from_pts; /* timestamp of the frame the flow starts at */
  GstClockTime to_pts;   /* timestamp of the frame the flow ends at (normally this buffer's) */
  guint64 from_frame;    /* frame numbers as counted by the element (0-based, all frames in) */
  guint64 to_frame;

  guint model_width; /* the resolution the network ran at */
  guint model_height;
  guint iters_s16; /* refinement iterations at 1/16 and 1/8 */
  guint iters_s8;
  GstClockTime inference_time; /* wall time of the computation */
} NeuflowFlowMeta;

GType neuflow_flow_meta_api_get_type(void);
const GstMetaInfo *neuflow_flow_meta_get_info(void);

/* Attaches a flow meta to `buffer` (which must be writable); takes a reference on `data`,
 * which must hold width * height * 2 floats. Returns the meta for filling the other fields. */
NeuflowFlowMeta *neuflow_buffer_add_flow_meta(GstBuffer *buffer, guint width, guint height, GBytes *data);

/* The flow meta on `buffer`, or NULL. */
NeuflowFlowMeta *neuflow_buffer_get_flow_meta(GstBuffer *buffer);

/* The (u, v) vectors of the grid: width * height * 2 floats. */
const gfloat *neuflow_flow_meta_get_vectors(const NeuflowFlowMeta *meta);

G_END_DECLS

#endif /* NEUFLOW_GST_FLOW_META_H */
