// Registration and transforms of NeuflowFlowMeta (see include/neuflow/gst/flow_meta.h).
#include "neuflow/gst/flow_meta.h"

#include <gst/video/video.h>

namespace {

gboolean flow_meta_init(GstMeta *meta, gpointer /*params*/, GstBuffer * /*buffer*/) {
  auto *m = reinterpret_cast<NeuflowFlowMeta *>(meta);
  m->width = m->height = m->frame_width = m->frame_height = 0;
  m->data = nullptr;
  m->from_pts = m->to_pts = GST_CLOCK_TIME_NONE;
  m->from_frame = m->to_frame = 0;
  m->model_width = m->model_height = m->iters_s16 = m->iters_s8 = 0;
  m->inference_time = GST_CLOCK_TIME_NONE;
  return TRUE;
}

void flow_meta_free(GstMeta *meta, GstBuffer * /*buffer*/) {
  auto *m = reinterpret_cast<NeuflowFlowMeta *>(meta);
  g_clear_pointer(&m->data, g_bytes_unref);
}

// Copies keep sharing the vectors; a scaling transform keeps the grid and records the new
// frame size, since the grid covers the whole frame whatever its size.
gboolean flow_meta_transform(GstBuffer *dest, GstMeta *meta, GstBuffer * /*src*/, GQuark type, gpointer data) {
  auto *src = reinterpret_cast<NeuflowFlowMeta *>(meta);
  guint frame_width = src->frame_width, frame_height = src->frame_height;
  if (GST_META_TRANSFORM_IS_COPY(type)) {
    // as is
  } else if (GST_VIDEO_META_TRANSFORM_IS_SCALE(type)) {
    auto *scale = static_cast<GstVideoMetaTransform *>(data);
    frame_width = static_cast<guint>(GST_VIDEO_INFO_WIDTH(scale->out_info));
    frame_height = static_cast<guint>(GST_VIDEO_INFO_HEIGHT(scale->out_info));
  } else {
    return FALSE;  // unknown transforms (crops, rotations) would break the mapping: drop the meta
  }
  NeuflowFlowMeta *out = neuflow_buffer_add_flow_meta(dest, src->width, src->height, src->data);
  if (!out) return FALSE;
  out->frame_width = frame_width;
  out->frame_height = frame_height;
  out->from_pts = src->from_pts;
  out->to_pts = src->to_pts;
  out->from_frame = src->from_frame;
  out->to_frame = src->to_frame;
  out->model_width = src->model_width;
  out->model_height = src->model_height;
  out->iters_s16 = src->iters_s16;
  out->iters_s8 = src->iters_s8;
  out->inference_time = src->inference_time;
  return TRUE;
}

}  // namespace

GType neuflow_flow_meta_api_get_type(void) {
  static GType type = 0;
  static const gchar *tags[] = {GST_META_TAG_VIDEO_STR, GST_META_TAG_VIDEO_SIZE_STR, nullptr};
  if (g_once_init_enter(&type)) {
    GType t = gst_meta_api_type_register("NeuflowFlowMetaAPI", tags);
    g_once_init_leave(&type, t);
  }
  return type;
}

const GstMetaInfo *neuflow_flow_meta_get_info(void) {
  static const GstMetaInfo *info = nullptr;
  if (g_once_init_enter(&info)) {
    const GstMetaInfo *i = gst_meta_register(NEUFLOW_FLOW_META_API_TYPE, "NeuflowFlowMeta", sizeof(NeuflowFlowMeta),
                                             flow_meta_init, flow_meta_free, flow_meta_transform);
    g_once_init_leave(&info, i);
  }
  return info;
}

NeuflowFlowMeta *neuflow_buffer_add_flow_meta(GstBuffer *buffer, guint width, guint height, GBytes *data) {
  g_return_val_if_fail(GST_IS_BUFFER(buffer), nullptr);
  g_return_val_if_fail(data != nullptr, nullptr);
  g_return_val_if_fail(g_bytes_get_size(data) == static_cast<gsize>(width) * height * 2 * sizeof(gfloat), nullptr);
  auto *m = reinterpret_cast<NeuflowFlowMeta *>(gst_buffer_add_meta(buffer, NEUFLOW_FLOW_META_INFO, nullptr));
  if (!m) return nullptr;
  m->width = width;
  m->height = height;
  m->frame_width = width;
  m->frame_height = height;
  m->data = g_bytes_ref(data);
  return m;
}

NeuflowFlowMeta *neuflow_buffer_get_flow_meta(GstBuffer *buffer) {
  return reinterpret_cast<NeuflowFlowMeta *>(gst_buffer_get_meta(buffer, NEUFLOW_FLOW_META_API_TYPE));
}

const gfloat *neuflow_flow_meta_get_vectors(const NeuflowFlowMeta *meta) {
  g_return_val_if_fail(meta != nullptr && meta->data != nullptr, nullptr);
  return static_cast<const gfloat *>(g_bytes_get_data(meta->data, nullptr));
}
