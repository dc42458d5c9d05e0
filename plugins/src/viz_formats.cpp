#include "viz_formats.hpp"

#include <gst/video/video.h>

namespace neuflow::gst {

namespace {

// The "format" value (a list) of caps made of these formats.
const GValue *format_list(bool with_converted) {
  static GstCaps *drawn = gst_caps_from_string(GST_VIDEO_CAPS_MAKE("{ " NEUFLOW_VIZ_DRAW_FORMATS " }"));
  static GstCaps *all =
      gst_caps_from_string(GST_VIDEO_CAPS_MAKE("{ " NEUFLOW_VIZ_DRAW_FORMATS ", " NEUFLOW_VIZ_CONVERTED_FORMATS " }"));
  return gst_structure_get_value(gst_caps_get_structure(with_converted ? all : drawn, 0), "format");
}

}  // namespace

GstCaps *viz_transform_caps(GstPadDirection direction, GstCaps *caps, GstCaps *filter, GstCaps *other_template) {
  // From the sink side (direction SINK) the other side is the src pad: drawable formats only.
  const GValue *formats = format_list(direction == GST_PAD_SRC);
  GstCaps *same = gst_caps_new_empty();
  GstCaps *converted = gst_caps_new_empty();
  for (guint i = 0; i < gst_caps_get_size(caps); ++i) {
    const GstStructure *structure = gst_caps_get_structure(caps, i);
    const GstCapsFeatures *features = gst_caps_get_features(caps, i);
    gst_caps_append_structure_full(same, gst_structure_copy(structure),
                                   features != nullptr ? gst_caps_features_copy(features) : nullptr);
    GstStructure *other = gst_structure_copy(structure);
    gst_structure_set_value(other, "format", formats);
    // A conversion between YUV and RGB changes what these mean (bt601 is no RGB colorimetry,
    // sRGB no YUV one): as videoconvert does, the other side chooses its own.
    gst_structure_remove_fields(other, "colorimetry", "chroma-site", nullptr);
    gst_caps_append_structure_full(converted, other, features != nullptr ? gst_caps_features_copy(features) : nullptr);
  }
  // The same format first, so a drawable one is kept and drawn in place.
  GstCaps *both = gst_caps_merge(same, converted);
  GstCaps *allowed = gst_caps_intersect_full(both, other_template, GST_CAPS_INTERSECT_FIRST);
  gst_caps_unref(both);
  if (filter == nullptr) return allowed;
  GstCaps *filtered = gst_caps_intersect_full(filter, allowed, GST_CAPS_INTERSECT_FIRST);
  gst_caps_unref(allowed);
  return filtered;
}

}  // namespace neuflow::gst
