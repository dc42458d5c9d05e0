#include "frame_converter.hpp"

namespace neuflow::gst {

FrameConverter::~FrameConverter() {
  if (converter_) gst_video_converter_free(converter_);
}

bool FrameConverter::set_format(const GstVideoInfo& info) {
  if (converter_) gst_video_converter_free(converter_);
  converter_ = nullptr;
  info_ = info;
  const GstVideoFormat format = GST_VIDEO_INFO_FORMAT(&info);
  if (format == GST_VIDEO_FORMAT_RGB || format == GST_VIDEO_FORMAT_BGR) return true;
  GstVideoInfo rgb_info;
  gst_video_info_set_format(&rgb_info, GST_VIDEO_FORMAT_RGB, GST_VIDEO_INFO_WIDTH(&info), GST_VIDEO_INFO_HEIGHT(&info));
  // The converter insists on matching rates and aspect; only the format changes.
  GST_VIDEO_INFO_FPS_N(&rgb_info) = GST_VIDEO_INFO_FPS_N(&info);
  GST_VIDEO_INFO_FPS_D(&rgb_info) = GST_VIDEO_INFO_FPS_D(&info);
  GST_VIDEO_INFO_PAR_N(&rgb_info) = GST_VIDEO_INFO_PAR_N(&info);
  GST_VIDEO_INFO_PAR_D(&rgb_info) = GST_VIDEO_INFO_PAR_D(&info);
  converter_ = gst_video_converter_new(&info_, &rgb_info, nullptr);
  return converter_ != nullptr;
}

model::ImageView FrameConverter::view(GstVideoFrame& frame) {
  const int width = GST_VIDEO_INFO_WIDTH(&info_), height = GST_VIDEO_INFO_HEIGHT(&info_);
  if (!converter_) {
    const bool rgb = GST_VIDEO_INFO_FORMAT(&info_) == GST_VIDEO_FORMAT_RGB;
    return {static_cast<const std::uint8_t*>(GST_VIDEO_FRAME_PLANE_DATA(&frame, 0)), width, height,
            GST_VIDEO_FRAME_PLANE_STRIDE(&frame, 0), rgb ? model::ChannelOrder::rgb : model::ChannelOrder::bgr};
  }
  GstVideoFrame out;
  GstVideoInfo rgb_info;
  gst_video_info_set_format(&rgb_info, GST_VIDEO_FORMAT_RGB, width, height);
  rgb_.resize(GST_VIDEO_INFO_SIZE(&rgb_info));
  GstBuffer* wrapped =
      gst_buffer_new_wrapped_full(GST_MEMORY_FLAG_NO_SHARE, rgb_.data(), rgb_.size(), 0, rgb_.size(), nullptr, nullptr);
  gst_video_frame_map(&out, &rgb_info, wrapped, GST_MAP_WRITE);
  gst_video_converter_frame(converter_, &frame, &out);
  const model::ImageView view{rgb_.data(), width, height, GST_VIDEO_FRAME_PLANE_STRIDE(&out, 0),
                              model::ChannelOrder::rgb};
  gst_video_frame_unmap(&out);
  gst_buffer_unref(wrapped);
  return view;
}

}  // namespace neuflow::gst
