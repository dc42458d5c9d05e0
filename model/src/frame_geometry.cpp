#include "frame_geometry.hpp"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include <stdexcept>
#include <string>

namespace neuflow::model {

FrameGeometry plan_geometry(int input_width, int input_height, const SessionOptions& options) {
  using L = SessionLimits;
  if (input_width < L::min_side || input_height < L::min_side || input_width > L::max_side ||
      input_height > L::max_side) {
    throw std::invalid_argument("frame size " + std::to_string(input_width) + "x" + std::to_string(input_height) +
                                " is outside the supported range 32x32 to 16384x16384");
  }
  FrameGeometry g;
  g.input_width = input_width;
  g.input_height = input_height;
  if (auto problem = check_model_size(options.model_width, options.model_height)) {
    throw std::invalid_argument(*problem);
  }
  const ModelSize size = model_size_for(input_width, input_height, options);
  g.model_width = size.width;
  g.model_height = size.height;
  g.resize = options.model_width > 0;
  if (!g.resize) {
    g.pad_left = (g.model_width - input_width) / 2;
    g.pad_top = (g.model_height - input_height) / 2;
  }
  return g;
}

void check_image(const ImageView& image, const FrameGeometry& g) {
  if (image.data == nullptr || image.width != g.input_width || image.height != g.input_height ||
      image.stride < static_cast<std::ptrdiff_t>(image.width) * 3) {
    throw std::invalid_argument("image does not match the session's frame size or has a short row stride");
  }
}

void prepare_input(const ImageView& image, const FrameGeometry& g, ChannelOrder network_order, Tensor& out) {
  check_image(image, g);
  const cv::Mat src(image.height, image.width, CV_8UC3, const_cast<std::uint8_t*>(image.data),
                    static_cast<std::size_t>(image.stride));
  cv::Mat ordered;
  if (image.order != network_order) {
    cv::cvtColor(src, ordered, cv::COLOR_BGR2RGB);  // the same swap either way
  } else {
    ordered = src;
  }
  cv::Mat sized;
  if (g.resize) {
    cv::resize(ordered, sized, cv::Size(g.model_width, g.model_height), 0, 0, cv::INTER_LINEAR);
  } else {
    cv::copyMakeBorder(ordered, sized, g.pad_top, g.model_height - g.input_height - g.pad_top, g.pad_left,
                       g.model_width - g.input_width - g.pad_left, cv::BORDER_REPLICATE);
  }
  out.resize(g.model_height, g.model_width, 3);
  cv::Mat dst(g.model_height, g.model_width, CV_32FC3, out.data.data());
  sized.convertTo(dst, CV_32FC3, 1.0 / 255.0);
}

flow::FlowField restore_flow(const Tensor& model_flow, const FrameGeometry& g) {
  flow::FlowField f(g.input_width, g.input_height);
  const cv::Mat src(model_flow.h, model_flow.w, CV_32FC2, const_cast<float*>(model_flow.data.data()));
  cv::Mat dst(g.input_height, g.input_width, CV_32FC2, f.uv.data());
  if (g.resize) {
    cv::resize(src, dst, dst.size(), 0, 0, cv::INTER_LINEAR);
    const float sx = static_cast<float>(g.input_width) / static_cast<float>(g.model_width);
    const float sy = static_cast<float>(g.input_height) / static_cast<float>(g.model_height);
    for (std::size_t p = 0; p < f.pixel_count(); ++p) {
      f.uv[2 * p] *= sx;
      f.uv[2 * p + 1] *= sy;
    }
  } else {
    src(cv::Rect(g.pad_left, g.pad_top, g.input_width, g.input_height)).copyTo(dst);
  }
  return f;
}

}  // namespace neuflow::model
