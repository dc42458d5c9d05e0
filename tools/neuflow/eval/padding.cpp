#include "neuflow/eval/padding.hpp"

#include <opencv2/core.hpp>

#include <algorithm>
#include <stdexcept>
#include <string>

namespace neuflow::eval {

Padding reference_padding(int width, int height, PadMode mode, int multiple) {
  if (width <= 0 || height <= 0 || multiple <= 0) {
    throw std::invalid_argument("reference_padding: size " + std::to_string(width) + "x" + std::to_string(height) +
                                " and multiple " + std::to_string(multiple) + " must be positive");
  }
  const int pad_w = (multiple - width % multiple) % multiple;
  const int pad_h = (multiple - height % multiple) % multiple;
  Padding p;
  p.left = pad_w / 2;
  p.right = pad_w - p.left;
  if (mode == PadMode::centred) {
    p.top = pad_h / 2;
    p.bottom = pad_h - p.top;
  } else {
    p.top = 0;
    p.bottom = pad_h;
  }
  return p;
}

cv::Mat pad_image(const cv::Mat& image, const Padding& padding) {
  cv::Mat padded;
  cv::copyMakeBorder(image, padded, padding.top, padding.bottom, padding.left, padding.right, cv::BORDER_REPLICATE);
  return padded;
}

flow::FlowField crop_flow(const flow::FlowField& padded, const Padding& padding) {
  const int width = padded.width - padding.left - padding.right;
  const int height = padded.height - padding.top - padding.bottom;
  if (width <= 0 || height <= 0 || std::min({padding.left, padding.right, padding.top, padding.bottom}) < 0) {
    throw std::invalid_argument("crop_flow: a " + std::to_string(padded.width) + "x" + std::to_string(padded.height) +
                                " field cannot lose padding left " + std::to_string(padding.left) + ", right " +
                                std::to_string(padding.right) + ", top " + std::to_string(padding.top) + ", bottom " +
                                std::to_string(padding.bottom));
  }
  flow::FlowField out(width, height);
  if (padded.has_mask()) out.valid.assign(out.pixel_count(), 0);
  for (int y = 0; y < height; ++y) {
    const auto src_row = static_cast<std::size_t>(y + padding.top) * padded.width + padding.left;
    const auto dst_row = static_cast<std::size_t>(y) * width;
    std::copy_n(padded.uv.begin() + static_cast<std::ptrdiff_t>(2 * src_row), 2 * width,
                out.uv.begin() + static_cast<std::ptrdiff_t>(2 * dst_row));
    if (padded.has_mask()) {
      std::copy_n(padded.valid.begin() + static_cast<std::ptrdiff_t>(src_row), width,
                  out.valid.begin() + static_cast<std::ptrdiff_t>(dst_row));
    }
  }
  return out;
}

}  // namespace neuflow::eval
