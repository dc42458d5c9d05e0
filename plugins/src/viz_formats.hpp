#pragma once
// neuflowviz's formats: it draws on packed 8-bit RGB frames in place, and takes the other raw
// formats `neuflow` passes through (GRAY8, I420, NV12, YUY2) too, converting them to RGB with
// GStreamer's own converter first, so `... ! neuflow ! neuflowviz ! ...` links whatever the
// camera delivers, without a videoconvert between them.
#include <gst/gst.h>

// The formats drawn on in place: the src pad's, and the sink pad's first choice.
#define NEUFLOW_VIZ_DRAW_FORMATS "RGB, BGR, RGBx, BGRx, xRGB, xBGR, RGBA, BGRA, ARGB, ABGR"
// The formats converted to one of those first.
#define NEUFLOW_VIZ_CONVERTED_FORMATS "GRAY8, I420, NV12, YUY2"

namespace neuflow::gst {

// GstBaseTransform::transform_caps for neuflowviz. Towards the src pad, a drawable format stays
// itself (drawn in place: preferred, listed first) and a converted one becomes any drawable one;
// towards the sink pad, a drawable format comes from itself or from any converted one. Sizes,
// rates and the other fields are kept; the result is limited to `other_template` (the other
// pad's template) and to `filter`.
GstCaps *viz_transform_caps(GstPadDirection direction, GstCaps *caps, GstCaps *filter, GstCaps *other_template);

}  // namespace neuflow::gst
