/**
 * SECTION:element-neuflowviz
 * @title: neuflowviz
 *
 * Draws the optical flow that rides on each video frame as a #NeuflowFlowMeta (attached by
 * the `neuflow` element), using the colour wheel of the Middlebury/Sintel flow tools:
 * hue is the direction (right = red, down = yellow, left = cyan, up = blue/violet), and
 * saturation the magnitude relative to #neuflowviz:max-flow (white = no motion; vectors
 * beyond it are drawn fully saturated and dimmed to 75%).
 *
 * The flow grid may be smaller than the frame (the network runs at a reduced resolution):
 * it is stretched over the whole frame and its vectors are scaled to frame pixels
 * (by frame width / grid width and frame height / grid height) before colouring, so
 * #neuflowviz:max-flow is always in pixels of the frame being drawn on.
 *
 * In `overlay` mode (the default) the flow image is blended over the video with
 * #neuflowviz:alpha; in `flow` mode it replaces the frame. #neuflowviz:arrows adds a grid of
 * anti-aliased arrows showing the displacement, scaled by #neuflowviz:arrow-scale (by default
 * a vector of #neuflowviz:max-flow pixels is one #neuflowviz:arrow-spacing long). Frames
 * without a flow meta (the first frame of a stream) pass through unchanged and uncopied in
 * overlay mode, and are drawn as zero flow (white) in flow mode, as `neuflow convert` renders
 * them.
 *
 * It draws on packed RGB frames in place, and takes every other format `neuflow` passes
 * through (GRAY8, I420, NV12, YUY2) as well: those are converted to RGB first, so no
 * `videoconvert` is needed between the two.
 *
 * ## Example launch line
 * |[
 * gst-launch-1.0 v4l2src ! videoconvert ! neuflow ! neuflowviz max-flow=30 alpha=0.6 arrows=true ! videoconvert ! autovideosink
 * ]|
 */
#include <gst/gst.h>
#include <gst/video/gstvideofilter.h>
#include <gst/video/video.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <exception>
#include <limits>
#include <optional>
#include <vector>

#include "elements.hpp"
#include "neuflow/flow/arrows.hpp"
#include "neuflow/flow/figures.hpp"
#include "neuflow/flow/flow_field.hpp"
#include "neuflow/flow/visualize.hpp"
#include "neuflow/gst/flow_meta.h"
#include "viz_formats.hpp"

GST_DEBUG_CATEGORY_STATIC(gst_neuflow_viz_debug);
#define GST_CAT_DEFAULT gst_neuflow_viz_debug

/* How the flow is drawn. */
typedef enum {
  GST_NEUFLOW_VIZ_MODE_OVERLAY = 0,
  GST_NEUFLOW_VIZ_MODE_FLOW = 1,
} GstNeuflowVizMode;

#define GST_TYPE_NEUFLOW_VIZ_MODE (gst_neuflow_viz_mode_get_type())

static GType gst_neuflow_viz_mode_get_type(void) {
  static GType type = 0;
  static const GEnumValue values[] = {
      {GST_NEUFLOW_VIZ_MODE_OVERLAY, "Blend the flow colours over the video (see alpha)", "overlay"},
      {GST_NEUFLOW_VIZ_MODE_FLOW, "Replace the video by the flow image", "flow"},
      {0, nullptr, nullptr},
  };
  if (g_once_init_enter(&type)) {
    GType t = g_enum_register_static("GstNeuflowVizMode", values);
    g_once_init_leave(&type, t);
  }
  return type;
}

enum {
  PROP_0,
  PROP_MAX_FLOW,
  PROP_MODE,
  PROP_ALPHA,
  PROP_ARROWS,
  PROP_ARROW_SPACING,
  PROP_ARROW_COLOR,
  PROP_ARROW_SCALE,
};

#define DEFAULT_PROP_MAX_FLOW 20.0
#define DEFAULT_PROP_MODE GST_NEUFLOW_VIZ_MODE_OVERLAY /* what a live view over the video wants */
#define DEFAULT_PROP_ALPHA neuflow::flow::kOverlayAlpha
#define DEFAULT_PROP_ARROWS FALSE
#define DEFAULT_PROP_ARROW_SPACING static_cast<guint>(neuflow::flow::kArrowSpacing)
#define DEFAULT_PROP_ARROW_COLOR 0xff000000u /* opaque black, 0xAARRGGBB */
#define DEFAULT_PROP_ARROW_SCALE 0.0         /* auto: a vector of max-flow pixels is arrow-spacing long */
#define MAX_ARROW_SCALE 1000.0

#define MIN_ARROW_SPACING 4u
#define MAX_ARROW_SPACING 4096u
#define MAX_MAX_FLOW 1e6

namespace {

struct VizSettings {
  gdouble max_flow = DEFAULT_PROP_MAX_FLOW;
  GstNeuflowVizMode mode = DEFAULT_PROP_MODE;
  gdouble alpha = DEFAULT_PROP_ALPHA;
  gboolean arrows = DEFAULT_PROP_ARROWS;
  guint arrow_spacing = DEFAULT_PROP_ARROW_SPACING;
  guint arrow_color = DEFAULT_PROP_ARROW_COLOR;
  gdouble arrow_scale = DEFAULT_PROP_ARROW_SCALE;
};

struct PixelLayout;
struct VizScratch;

using ComposeFunction = void (*)(GstVideoFrame *frame, const PixelLayout &px, const neuflow::flow::RgbImage &image,
                                 VizScratch &s, int weight256);

// Where R, G and B sit inside one pixel of the negotiated packed format, and the routines
// that draw into it; chosen once per caps in set_info.
struct PixelLayout {
  int r = 0, g = 1, b = 2;
  int stride = 3;                     // bytes per pixel
  ComposeFunction replace = nullptr;  // flow mode
  ComposeFunction overlay = nullptr;  // overlay mode
};

// Per-frame scratch kept between frames to avoid reallocating: the grid with vectors in
// frame pixels, and the bilinear sampling tables from frame columns to grid columns.
struct VizScratch {
  neuflow::flow::FlowField field;
  std::vector<int> x0, x1, wx;           // column -> grid columns and weight of x1 (0..256)
  std::vector<int> y0, y1, wy;           // the same for rows
  std::vector<int> row;                  // one output row's blend of its two grid rows, RGB
  std::vector<std::uint8_t> arrow_mask;  // the arrows' anti-aliased coverage, 0..255
};

}  // namespace

struct GstNeuflowViz {
  GstVideoFilter parent;

  VizSettings settings;  // properties, under the object lock

  // Streaming thread only.
  PixelLayout layout;
  VizScratch *scratch;
  // From the negotiated input format to the drawn one; null when the frames are drawn on in place.
  GstVideoConverter *converter;
};

struct GstNeuflowVizClass {
  GstVideoFilterClass parent_class;
};

#define GST_NEUFLOW_VIZ(obj) (reinterpret_cast<GstNeuflowViz *>(obj))

G_DEFINE_TYPE_WITH_CODE(GstNeuflowViz, gst_neuflow_viz, GST_TYPE_VIDEO_FILTER,
                        GST_DEBUG_CATEGORY_INIT(gst_neuflow_viz_debug, "neuflowviz", 0,
                                                "NeuFlow optical flow visualization"))

static GstStaticPadTemplate sink_template = GST_STATIC_PAD_TEMPLATE(
    "sink", GST_PAD_SINK, GST_PAD_ALWAYS,
    GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("{ " NEUFLOW_VIZ_DRAW_FORMATS ", " NEUFLOW_VIZ_CONVERTED_FORMATS " }")));
static GstStaticPadTemplate src_template = GST_STATIC_PAD_TEMPLATE(
    "src", GST_PAD_SRC, GST_PAD_ALWAYS, GST_STATIC_CAPS(GST_VIDEO_CAPS_MAKE("{ " NEUFLOW_VIZ_DRAW_FORMATS " }")));

namespace {

inline std::uint8_t blend(int under, int over, int weight256) {
  return static_cast<std::uint8_t>((under * (256 - weight256) + over * weight256 + 128) >> 8);
}

// Sampling tables mapping n output positions onto a grid of m cells, pixel centres aligned,
// clamped at the borders: output i takes (1 - w) * cell i0 + w * cell i1, w in 1/256.
void bilinear_tables(int n, int m, std::vector<int> &i0, std::vector<int> &i1, std::vector<int> &w) {
  i0.resize(static_cast<std::size_t>(n));
  i1.resize(static_cast<std::size_t>(n));
  w.resize(static_cast<std::size_t>(n));
  const double scale = static_cast<double>(m) / n;
  for (int i = 0; i < n; ++i) {
    const double g = std::clamp((i + 0.5) * scale - 0.5, 0.0, static_cast<double>(m - 1));
    const int lo = std::min(static_cast<int>(g), m - 1);
    const auto k = static_cast<std::size_t>(i);
    i0[k] = lo;
    i1[k] = std::min(lo + 1, m - 1);
    w[k] = static_cast<int>(std::lround((g - lo) * 256.0));
  }
}

// Writes the flow colours (grid image stretched bilinearly to the frame) into the frame,
// replacing it or blending over it with weight256 / 256. Separable: each output row first
// blends its two grid rows (into s.row), then each pixel its two columns; in integers, the
// same sums as a direct bilinear interpolation.
template <int kPixelStride, bool kReplace>
void compose_flow(GstVideoFrame *frame, const PixelLayout &px, const neuflow::flow::RgbImage &image, VizScratch &s,
                  int weight256) {
  const int fw = GST_VIDEO_FRAME_WIDTH(frame);
  const int fh = GST_VIDEO_FRAME_HEIGHT(frame);
  auto *data = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_PLANE_DATA(frame, 0));
  const int stride = GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0);
  const std::size_t row_len = 3 * static_cast<std::size_t>(image.width);
  bilinear_tables(fw, image.width, s.x0, s.x1, s.wx);
  bilinear_tables(fh, image.height, s.y0, s.y1, s.wy);
  for (std::size_t x = 0; x < s.x0.size(); ++x) {  // columns as offsets into an RGB row
    s.x0[x] *= 3;
    s.x1[x] *= 3;
  }
  s.row.resize(row_len);

  const std::uint8_t *rgb = image.rgb.data();
  const int r = px.r, g = px.g, b = px.b;
  for (int y = 0; y < fh; ++y) {
    const auto ky = static_cast<std::size_t>(y);
    const std::uint8_t *row0 = rgb + static_cast<std::size_t>(s.y0[ky]) * row_len;
    const std::uint8_t *row1 = rgb + static_cast<std::size_t>(s.y1[ky]) * row_len;
    const int wb = s.wy[ky], wa = 256 - wb;
    int *mixed = s.row.data();
    for (std::size_t i = 0; i < row_len; ++i) mixed[i] = row0[i] * wa + row1[i] * wb;

    std::uint8_t *out = data + static_cast<std::ptrdiff_t>(y) * stride;
    for (int x = 0; x < fw; ++x, out += kPixelStride) {
      const auto kx = static_cast<std::size_t>(x);
      const int *c0 = mixed + s.x0[kx];
      const int *c1 = mixed + s.x1[kx];
      const int wd = s.wx[kx], wc = 256 - wd;
      const int cr = (c0[0] * wc + c1[0] * wd + (1 << 15)) >> 16;
      const int cg = (c0[1] * wc + c1[1] * wd + (1 << 15)) >> 16;
      const int cb = (c0[2] * wc + c1[2] * wd + (1 << 15)) >> 16;
      if constexpr (kReplace) {
        out[r] = static_cast<std::uint8_t>(cr);
        out[g] = static_cast<std::uint8_t>(cg);
        out[b] = static_cast<std::uint8_t>(cb);
      } else {
        out[r] = blend(out[r], cr, weight256);
        out[g] = blend(out[g], cg, weight256);
        out[b] = blend(out[b], cb, weight256);
      }
    }
  }
}

// The arrows of flow/arrows.hpp, blended in the colour 0xAARRGGBB.
void draw_arrows(GstVideoFrame *frame, const PixelLayout &px, const neuflow::flow::FlowField &field, guint spacing,
                 double scale, double max_length, guint argb, std::vector<std::uint8_t> &mask) {
  const int fw = GST_VIDEO_FRAME_WIDTH(frame);
  const int fh = GST_VIDEO_FRAME_HEIGHT(frame);
  neuflow::flow::arrow_coverage(field, fw, fh, static_cast<int>(spacing), scale, max_length, mask);
  const int a = static_cast<int>((argb >> 24) & 0xff);
  const int color[3] = {static_cast<int>((argb >> 16) & 0xff), static_cast<int>((argb >> 8) & 0xff),
                        static_cast<int>(argb & 0xff)};
  auto *data = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_PLANE_DATA(frame, 0));
  const int stride = GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0);
  for (int y = 0; y < fh; ++y) {
    const std::uint8_t *m = mask.data() + static_cast<std::ptrdiff_t>(y) * fw;
    std::uint8_t *p = data + static_cast<std::ptrdiff_t>(y) * stride;
    for (int x = 0; x < fw; ++x, p += px.stride) {
      if (m[x] == 0) continue;
      const int w = (m[x] * a + 127) / 255;  // coverage × opacity
      const int offsets[3] = {px.r, px.g, px.b};
      for (int c = 0; c < 3; ++c) {
        p[offsets[c]] = static_cast<std::uint8_t>((p[offsets[c]] * (255 - w) + color[c] * w + 127) / 255);
      }
    }
  }
}

}  // namespace

static void gst_neuflow_viz_set_property(GObject *object, guint prop_id, const GValue *value, GParamSpec *pspec) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_MAX_FLOW: self->settings.max_flow = g_value_get_double(value); break;
    case PROP_MODE: self->settings.mode = static_cast<GstNeuflowVizMode>(g_value_get_enum(value)); break;
    case PROP_ALPHA: self->settings.alpha = g_value_get_double(value); break;
    case PROP_ARROWS: self->settings.arrows = g_value_get_boolean(value); break;
    case PROP_ARROW_SPACING: self->settings.arrow_spacing = g_value_get_uint(value); break;
    case PROP_ARROW_COLOR: self->settings.arrow_color = g_value_get_uint(value); break;
    case PROP_ARROW_SCALE: self->settings.arrow_scale = g_value_get_double(value); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_viz_get_property(GObject *object, guint prop_id, GValue *value, GParamSpec *pspec) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(object);
  GST_OBJECT_LOCK(self);
  switch (prop_id) {
    case PROP_MAX_FLOW: g_value_set_double(value, self->settings.max_flow); break;
    case PROP_MODE: g_value_set_enum(value, self->settings.mode); break;
    case PROP_ALPHA: g_value_set_double(value, self->settings.alpha); break;
    case PROP_ARROWS: g_value_set_boolean(value, self->settings.arrows); break;
    case PROP_ARROW_SPACING: g_value_set_uint(value, self->settings.arrow_spacing); break;
    case PROP_ARROW_COLOR: g_value_set_uint(value, self->settings.arrow_color); break;
    case PROP_ARROW_SCALE: g_value_set_double(value, self->settings.arrow_scale); break;
    default: G_OBJECT_WARN_INVALID_PROPERTY_ID(object, prop_id, pspec); break;
  }
  GST_OBJECT_UNLOCK(self);
}

static void gst_neuflow_viz_finalize(GObject *object) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(object);
  delete self->scratch;
  self->scratch = nullptr;
  if (self->converter != nullptr) gst_video_converter_free(self->converter);
  self->converter = nullptr;
  G_OBJECT_CLASS(gst_neuflow_viz_parent_class)->finalize(object);
}

static GstCaps *gst_neuflow_viz_transform_caps(GstBaseTransform *trans, GstPadDirection direction, GstCaps *caps,
                                               GstCaps *filter) {
  GstPad *other = direction == GST_PAD_SINK ? GST_BASE_TRANSFORM_SRC_PAD(trans) : GST_BASE_TRANSFORM_SINK_PAD(trans);
  GstCaps *other_template = gst_pad_get_pad_template_caps(other);
  GstCaps *result = neuflow::gst::viz_transform_caps(direction, caps, filter, other_template);
  gst_caps_unref(other_template);
  GST_DEBUG_OBJECT(trans, "%" GST_PTR_FORMAT " -> %" GST_PTR_FORMAT, static_cast<void *>(caps),
                   static_cast<void *>(result));
  return result;
}

// The per-format choice: where R, G and B are in a pixel of the drawn format, and whether the
// frames are converted to it first.
static gboolean gst_neuflow_viz_set_info(GstVideoFilter *filter, GstCaps * /*incaps*/, GstVideoInfo *in_info,
                                         GstCaps * /*outcaps*/, GstVideoInfo *out_info) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(filter);
  if (self->converter != nullptr) gst_video_converter_free(self->converter);
  self->converter = nullptr;
  const bool convert = GST_VIDEO_INFO_FORMAT(in_info) != GST_VIDEO_INFO_FORMAT(out_info);
  if (convert) {
    self->converter = gst_video_converter_new(in_info, out_info, nullptr);
    if (self->converter == nullptr) {
      GST_ERROR_OBJECT(self, "cannot convert %s to %s", GST_VIDEO_INFO_NAME(in_info), GST_VIDEO_INFO_NAME(out_info));
      return FALSE;
    }
  }
  gst_base_transform_set_in_place(GST_BASE_TRANSFORM(filter), !convert);
  const GstVideoFormatInfo *finfo = out_info->finfo;
  if (!GST_VIDEO_FORMAT_INFO_IS_RGB(finfo) || GST_VIDEO_FORMAT_INFO_N_PLANES(finfo) != 1 ||
      GST_VIDEO_FORMAT_INFO_BITS(finfo) != 8) {
    GST_ERROR_OBJECT(self, "unsupported format %s", GST_VIDEO_FORMAT_INFO_NAME(finfo));
    return FALSE;
  }
  self->layout.r = static_cast<int>(GST_VIDEO_INFO_COMP_POFFSET(out_info, GST_VIDEO_COMP_R));
  self->layout.g = static_cast<int>(GST_VIDEO_INFO_COMP_POFFSET(out_info, GST_VIDEO_COMP_G));
  self->layout.b = static_cast<int>(GST_VIDEO_INFO_COMP_POFFSET(out_info, GST_VIDEO_COMP_B));
  self->layout.stride = GST_VIDEO_INFO_COMP_PSTRIDE(out_info, 0);
  if (self->layout.stride == 3) {
    self->layout.replace = compose_flow<3, true>;
    self->layout.overlay = compose_flow<3, false>;
  } else if (self->layout.stride == 4) {
    self->layout.replace = compose_flow<4, true>;
    self->layout.overlay = compose_flow<4, false>;
  } else {
    GST_ERROR_OBJECT(self, "unsupported pixel size %d in %s", self->layout.stride, GST_VIDEO_FORMAT_INFO_NAME(finfo));
    return FALSE;
  }
  GST_DEBUG_OBJECT(self, "%s%s: R at %d, G at %d, B at %d, %d bytes per pixel", convert ? "converted to " : "format ",
                   GST_VIDEO_FORMAT_INFO_NAME(finfo), self->layout.r, self->layout.g, self->layout.b,
                   self->layout.stride);
  return TRUE;
}

// In overlay mode, frames without flow go through untouched: passthrough avoids copying a
// non-writable buffer that would not be modified anyway. In flow mode they are drawn as zero
// flow (white), so a rendering does not flash the camera picture at its start.
static void gst_neuflow_viz_before_transform(GstBaseTransform *trans, GstBuffer *buffer) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(trans);
  GST_OBJECT_LOCK(self);
  const bool flow_mode = self->settings.mode == GST_NEUFLOW_VIZ_MODE_FLOW;
  GST_OBJECT_UNLOCK(self);
  // A converted frame is always a new buffer.
  const bool draw = flow_mode || self->converter != nullptr || neuflow_buffer_get_flow_meta(buffer) != nullptr;
  if ((gst_base_transform_is_passthrough(trans) != FALSE) == draw) {
    GST_LOG_OBJECT(trans, "%s", draw ? "drawing" : "no flow meta: passing through");
    gst_base_transform_set_passthrough(trans, !draw);
  }
}

// Every pixel white (zero flow in the Middlebury convention); alpha and padding bytes kept.
static void fill_zero_flow(GstVideoFrame *frame, const PixelLayout &px) {
  auto *data = static_cast<std::uint8_t *>(GST_VIDEO_FRAME_PLANE_DATA(frame, 0));
  const int stride = GST_VIDEO_FRAME_PLANE_STRIDE(frame, 0);
  for (int y = 0; y < GST_VIDEO_FRAME_HEIGHT(frame); ++y) {
    std::uint8_t *p = data + static_cast<std::ptrdiff_t>(y) * stride;
    for (int x = 0; x < GST_VIDEO_FRAME_WIDTH(frame); ++x, p += px.stride) p[px.r] = p[px.g] = p[px.b] = 255;
  }
}

static GstFlowReturn draw_flow(GstNeuflowViz *self, GstVideoFrame *frame, NeuflowFlowMeta *meta) {
  GST_OBJECT_LOCK(self);
  const VizSettings settings = self->settings;
  GST_OBJECT_UNLOCK(self);
  if (!meta || meta->width == 0 || meta->height == 0) {
    if (settings.mode == GST_NEUFLOW_VIZ_MODE_FLOW) fill_zero_flow(frame, self->layout);
    return GST_FLOW_OK;
  }

  const int fw = GST_VIDEO_FRAME_WIDTH(frame);
  const int fh = GST_VIDEO_FRAME_HEIGHT(frame);
  if (meta->frame_width != static_cast<guint>(fw) || meta->frame_height != static_cast<guint>(fh)) {
    GST_LOG_OBJECT(self, "flow meta covers %ux%u, frame is %dx%d: stretching the grid over the frame",
                   meta->frame_width, meta->frame_height, fw, fh);
  }

  try {
    // The grid with its vectors in pixels of this frame.
    VizScratch &s = *self->scratch;
    const int gw = static_cast<int>(meta->width), gh = static_cast<int>(meta->height);
    if (s.field.width != gw || s.field.height != gh) s.field = neuflow::flow::FlowField(gw, gh);
    const float sx = static_cast<float>(fw) / static_cast<float>(gw);
    const float sy = static_cast<float>(fh) / static_cast<float>(gh);
    const gfloat *vectors = neuflow_flow_meta_get_vectors(meta);
    for (std::size_t i = 0; i < s.field.pixel_count(); ++i) {
      s.field.uv[2 * i] = vectors[2 * i] * sx;
      s.field.uv[2 * i + 1] = vectors[2 * i + 1] * sy;
    }

    neuflow::flow::VisualizeOptions options;
    if (settings.max_flow > 0) options.max_flow = settings.max_flow;
    const neuflow::flow::Visualization vis = neuflow::flow::visualize_flow(s.field, options);
    GST_LOG_OBJECT(self, "grid %dx%d onto %dx%d, max flow %.2f px", gw, gh, fw, fh, vis.max_flow);

    const int weight = settings.mode == GST_NEUFLOW_VIZ_MODE_FLOW
                           ? 256
                           : static_cast<int>(std::lround(std::clamp(settings.alpha, 0.0, 1.0) * 256.0));
    if (weight >= 256) {
      self->layout.replace(frame, self->layout, vis.image, s, 256);
    } else if (weight > 0) {
      self->layout.overlay(frame, self->layout, vis.image, s, weight);
    }
    if (settings.arrows) {
      // Auto scale: a vector of max-flow pixels (this frame's largest when max-flow is 0) is
      // one arrow-spacing long, and longer ones are drawn that long, so arrows stay in their cell.
      const neuflow::flow::ArrowScale scale =
          settings.arrow_scale <= 0
              ? neuflow::flow::automatic_arrow_scale(static_cast<int>(settings.arrow_spacing), vis.max_flow)
              : neuflow::flow::ArrowScale{settings.arrow_scale, std::numeric_limits<double>::infinity()};
      draw_arrows(frame, self->layout, s.field, settings.arrow_spacing, scale.scale, scale.max_length,
                  settings.arrow_color, s.arrow_mask);
    }
  } catch (const std::exception &e) {
    GST_ELEMENT_ERROR(self, STREAM, FAILED, ("Could not draw the optical flow: %s", e.what()), (nullptr));
    return GST_FLOW_ERROR;
  }
  return GST_FLOW_OK;
}

static GstFlowReturn gst_neuflow_viz_transform_frame_ip(GstVideoFilter *filter, GstVideoFrame *frame) {
  return draw_flow(GST_NEUFLOW_VIZ(filter), frame, neuflow_buffer_get_flow_meta(frame->buffer));
}

static GstFlowReturn gst_neuflow_viz_transform_frame(GstVideoFilter *filter, GstVideoFrame *in_frame,
                                                     GstVideoFrame *out_frame) {
  GstNeuflowViz *self = GST_NEUFLOW_VIZ(filter);
  gst_video_converter_frame(self->converter, in_frame, out_frame);
  return draw_flow(self, out_frame, neuflow_buffer_get_flow_meta(in_frame->buffer));
}

// The flow belongs to the frame whatever its colour format: a converted frame keeps it for
// the elements after this one (neuflowsink, neuflowshmsink).
static gboolean gst_neuflow_viz_transform_meta(GstBaseTransform *trans, GstBuffer *outbuf, GstMeta *meta,
                                               GstBuffer *inbuf) {
  if (meta->info->api == NEUFLOW_FLOW_META_API_TYPE) return TRUE;
  return GST_BASE_TRANSFORM_CLASS(gst_neuflow_viz_parent_class)->transform_meta(trans, outbuf, meta, inbuf);
}

static void gst_neuflow_viz_class_init(GstNeuflowVizClass *klass) {
  GObjectClass *gobject_class = G_OBJECT_CLASS(klass);
  GstElementClass *element_class = GST_ELEMENT_CLASS(klass);
  GstBaseTransformClass *trans_class = GST_BASE_TRANSFORM_CLASS(klass);
  GstVideoFilterClass *filter_class = GST_VIDEO_FILTER_CLASS(klass);

  gobject_class->set_property = gst_neuflow_viz_set_property;
  gobject_class->get_property = gst_neuflow_viz_get_property;
  gobject_class->finalize = gst_neuflow_viz_finalize;

  constexpr auto rw = static_cast<GParamFlags>(G_PARAM_READWRITE | G_PARAM_STATIC_STRINGS | GST_PARAM_MUTABLE_PLAYING);

  g_object_class_install_property(
      gobject_class, PROP_MAX_FLOW,
      g_param_spec_double("max-flow", "Maximum flow",
                          "Flow magnitude in pixels of the frame that maps to full colour saturation; longer "
                          "vectors are drawn saturated and dimmed. A fixed value keeps colours comparable from "
                          "frame to frame. 0 normalizes every frame by its own largest vector, which makes "
                          "colours flicker as the motion changes",
                          0.0, MAX_MAX_FLOW, DEFAULT_PROP_MAX_FLOW, rw));
  g_object_class_install_property(
      gobject_class, PROP_MODE,
      g_param_spec_enum("mode", "Mode", "Whether the flow image replaces the video or is blended over it",
                        GST_TYPE_NEUFLOW_VIZ_MODE, DEFAULT_PROP_MODE, rw));
  g_object_class_install_property(
      gobject_class, PROP_ALPHA,
      g_param_spec_double("alpha", "Alpha",
                          "Opacity of the flow colours in overlay mode (0 = video only, 1 = flow only); "
                          "ignored in flow mode",
                          0.0, 1.0, DEFAULT_PROP_ALPHA, rw));
  g_object_class_install_property(
      gobject_class, PROP_ARROWS,
      g_param_spec_boolean("arrows", "Arrows",
                           "Draw a grid of anti-aliased arrows, one per arrow-spacing pixels, each showing the "
                           "displacement at its starting point, scaled by arrow-scale",
                           DEFAULT_PROP_ARROWS, rw));
  g_object_class_install_property(
      gobject_class, PROP_ARROW_SPACING,
      g_param_spec_uint("arrow-spacing", "Arrow spacing", "Distance in frame pixels between neighbouring arrows",
                        MIN_ARROW_SPACING, MAX_ARROW_SPACING, DEFAULT_PROP_ARROW_SPACING, rw));
  g_object_class_install_property(
      gobject_class, PROP_ARROW_COLOR,
      g_param_spec_uint("arrow-color", "Arrow colour",
                        "Colour of the arrows as 0xAARRGGBB (AA = opacity; default opaque black, 0xFF000000, which "
                        "gst-inspect-1.0 prints in decimal as 4278190080)",
                        0, G_MAXUINT32, DEFAULT_PROP_ARROW_COLOR, rw));
  g_object_class_install_property(
      gobject_class, PROP_ARROW_SCALE,
      g_param_spec_double("arrow-scale", "Arrow scale",
                          "Arrow length per pixel of displacement (1: true length). 0: automatic, a vector of "
                          "max-flow pixels is drawn arrow-spacing long and longer ones no longer, so arrows stay "
                          "within their cell",
                          0.0, MAX_ARROW_SCALE, DEFAULT_PROP_ARROW_SCALE, rw));

  gst_element_class_set_static_metadata(element_class, "NeuFlow optical flow visualization",
                                        "Filter/Effect/Video/Analyzer",
                                        "Draws the optical flow attached to video frames (NeuflowFlowMeta) with the "
                                        "Middlebury colour wheel, as an image or an overlay, optionally with arrows",
                                        "neuflow");
  gst_element_class_add_static_metadata(element_class, GST_ELEMENT_METADATA_DOC_URI, NEUFLOW_DOC_URI);
  gst_element_class_add_static_pad_template(element_class, &sink_template);
  gst_element_class_add_static_pad_template(element_class, &src_template);

  trans_class->transform_caps = GST_DEBUG_FUNCPTR(gst_neuflow_viz_transform_caps);
  trans_class->before_transform = GST_DEBUG_FUNCPTR(gst_neuflow_viz_before_transform);
  trans_class->transform_ip_on_passthrough = FALSE;
  trans_class->transform_meta = GST_DEBUG_FUNCPTR(gst_neuflow_viz_transform_meta);
  filter_class->set_info = GST_DEBUG_FUNCPTR(gst_neuflow_viz_set_info);
  filter_class->transform_frame_ip = GST_DEBUG_FUNCPTR(gst_neuflow_viz_transform_frame_ip);
  filter_class->transform_frame = GST_DEBUG_FUNCPTR(gst_neuflow_viz_transform_frame);

  gst_type_mark_as_plugin_api(GST_TYPE_NEUFLOW_VIZ_MODE, static_cast<GstPluginAPIFlags>(0));
}

static void gst_neuflow_viz_init(GstNeuflowViz *self) {
  self->settings = VizSettings{};
  self->layout = PixelLayout{};
  self->scratch = new VizScratch();
  self->converter = nullptr;
}

GST_ELEMENT_REGISTER_DEFINE(neuflowviz, "neuflowviz", GST_RANK_NONE, gst_neuflow_viz_get_type());
