#pragma once
// Frames as the flow session takes them: packed RGB or BGR pass through untouched, any other
// raw format is converted to RGB (GstVideoConverter) into a buffer reused frame after frame.
#include <gst/video/video.h>

#include <vector>

#include "neuflow/model/image_view.hpp"

namespace neuflow::gst {

class FrameConverter {
 public:
  FrameConverter() = default;
  ~FrameConverter();
  FrameConverter(const FrameConverter&) = delete;
  FrameConverter& operator=(const FrameConverter&) = delete;

  // For frames described by `info`; false when GStreamer has no conversion from its format.
  bool set_format(const GstVideoInfo& info);

  // The frame's pixels (mapped with the info given to set_format), valid until the next call.
  model::ImageView view(GstVideoFrame& frame);

 private:
  GstVideoInfo info_{};
  GstVideoConverter* converter_ = nullptr;  // null for RGB and BGR
  std::vector<guint8> rgb_;
};

}  // namespace neuflow::gst
