#include "neuflow/flow/figures.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "neuflow/flow/arrows.hpp"

namespace neuflow::flow {

namespace {

void check_image(const RgbImage& image) {
  if (image.width < 1 || image.height < 1 ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * image.height) {
    throw std::invalid_argument("an empty or inconsistent picture");
  }
}

// The picture as an OpenCV matrix sharing its pixels (RGB order: colours are given as RGB).
cv::Mat as_mat(RgbImage& image) { return {image.height, image.width, CV_8UC3, image.rgb.data()}; }

// Text sizes that read at the picture's scale: Hershey simplex from 0.35 (tiny pictures) to 0.8.
double font_scale(const RgbImage& image) { return std::clamp(std::min(image.width, image.height) / 600.0, 0.35, 0.8); }

// Text at (x, baseline y), white on a dark box; returns the box's width.
int boxed_text(cv::Mat& mat, const std::string& text, int x, int y, double scale) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  const int pad = 3;
  cv::rectangle(mat, cv::Point(x - pad, y - size.height - pad), cv::Point(x + size.width + pad, y + baseline + pad),
                cv::Scalar(32, 32, 32), cv::FILLED);
  cv::putText(mat, text, cv::Point(x, y), cv::FONT_HERSHEY_SIMPLEX, scale, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  return size.width + 2 * pad;
}

std::string pixels(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, v >= 100 ? "%.0f px" : v >= 10 ? "%.1f px" : "%.2f px", v);
  return buf;
}

constexpr std::uint8_t kUnscoredGrey = 96;

// OpenCV's inferno map, index 0..255, as RGB.
const std::vector<Rgb8>& inferno() {
  static const std::vector<Rgb8> table = [] {
    cv::Mat ramp(1, 256, CV_8UC1);
    for (int i = 0; i < 256; ++i) ramp.at<std::uint8_t>(0, i) = static_cast<std::uint8_t>(i);
    cv::Mat bgr;
    cv::applyColorMap(ramp, bgr, cv::COLORMAP_INFERNO);
    std::vector<Rgb8> rgb(256);
    for (int i = 0; i < 256; ++i) {
      const auto p = bgr.at<cv::Vec3b>(0, i);
      rgb[static_cast<std::size_t>(i)] = {p[2], p[1], p[0]};
    }
    return rgb;
  }();
  return table;
}

}  // namespace

void draw_key(RgbImage& image, double max_flow) {
  check_image(image);
  const int radius = std::clamp(std::min(image.width, image.height) / 6, 12, 64);
  const int margin = std::max(4, radius / 4);
  const int cx = image.width - margin - radius, cy = image.height - margin - radius;
  for (int y = std::max(0, cy - radius); y <= std::min(image.height - 1, cy + radius); ++y) {
    for (int x = std::max(0, cx - radius); x <= std::min(image.width - 1, cx + radius); ++x) {
      const double u = static_cast<double>(x - cx) / radius, v = static_cast<double>(y - cy) / radius;
      if (u * u + v * v > 1.0) continue;
      const Rgb8 c = flow_color(u, v);
      std::copy(c.begin(), c.end(), image.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * image.width + x));
    }
  }
  cv::Mat mat = as_mat(image);
  cv::circle(mat, cv::Point(cx, cy), radius, cv::Scalar(32, 32, 32), 1, cv::LINE_AA);
  const std::string label = pixels(max_flow);
  const double scale = font_scale(image);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(label, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  boxed_text(mat, label, std::max(3, cx - radius - margin - size.width - 3), cy + size.height / 2, scale);
}

void draw_arrows(RgbImage& image, const FlowField& field, int spacing, double scale, double max_length, Rgb8 colour) {
  check_image(image);
  std::vector<std::uint8_t> coverage;
  arrow_coverage(field, image.width, image.height, spacing, scale, max_length, coverage);
  for (std::size_t i = 0; i < coverage.size(); ++i) {
    const int w = coverage[i];
    if (w == 0) continue;
    for (std::size_t c = 0; c < 3; ++c) {
      std::uint8_t& p = image.rgb[3 * i + c];
      p = static_cast<std::uint8_t>((p * (255 - w) + colour[c] * w + 127) / 255);
    }
  }
}

RgbImage blend(const RgbImage& under, const RgbImage& over, double alpha) {
  check_image(under);
  check_image(over);
  if (under.width != over.width || under.height != over.height) {
    throw std::invalid_argument("cannot blend a " + std::to_string(over.width) + "x" + std::to_string(over.height) +
                                " rendering onto a " + std::to_string(under.width) + "x" +
                                std::to_string(under.height) + " picture");
  }
  if (!(alpha >= 0 && alpha <= 1)) throw std::invalid_argument("the opacity must be between 0 and 1");
  RgbImage out = under;
  const int w = static_cast<int>(std::lround(alpha * 256));
  for (std::size_t i = 0; i < out.rgb.size(); ++i) {
    out.rgb[i] = static_cast<std::uint8_t>((under.rgb[i] * (256 - w) + over.rgb[i] * w + 128) >> 8);
  }
  return out;
}

RgbImage error_map(const FlowField& predicted, const FlowField& ground_truth, double max_error) {
  if (predicted.width != ground_truth.width || predicted.height != ground_truth.height) {
    throw std::invalid_argument("the prediction and the ground truth differ in size");
  }
  const int w = ground_truth.width, h = ground_truth.height;
  std::vector<double> epe(static_cast<std::size_t>(w) * h, -1.0);
  double largest = 0;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (!ground_truth.is_valid(x, y) || !std::isfinite(ground_truth.u(x, y)) ||
          !std::isfinite(ground_truth.v(x, y))) {
        continue;
      }
      const double e = std::hypot(predicted.u(x, y) - ground_truth.u(x, y), predicted.v(x, y) - ground_truth.v(x, y));
      epe[static_cast<std::size_t>(y) * w + x] = std::isfinite(e) ? e : INFINITY;
      if (std::isfinite(e)) largest = std::max(largest, e);
    }
  }
  const double top = max_error > 0 ? max_error : std::max(largest, 1.0);
  // Unscored pixels grey: the map's own darkest colour is (almost) black, no error.
  RgbImage image{w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h, kUnscoredGrey)};
  const auto& map = inferno();
  for (std::size_t i = 0; i < epe.size(); ++i) {
    if (epe[i] < 0) continue;
    const auto level = static_cast<std::size_t>(std::lround(std::min(1.0, epe[i] / top) * 255));
    std::copy(map[level].begin(), map[level].end(), image.rgb.begin() + static_cast<std::ptrdiff_t>(3 * i));
  }

  // The bar at the right edge: 0 at its bottom, max_error at its top, with both labels.
  const int bar_w = std::clamp(w / 40, 4, 16), bar_h = std::max(8, h * 3 / 5);
  const int right = w - std::max(3, w / 80), left = right - bar_w;
  const int bottom = h - std::max(3, h / 10), upper = bottom - bar_h;
  if (left > 0 && upper > 0) {
    for (int y = upper; y < bottom; ++y) {
      const auto level = static_cast<std::size_t>(std::lround(255.0 * (bottom - 1 - y) / std::max(1, bar_h - 1)));
      for (int x = left; x < right; ++x) {
        std::copy(map[level].begin(), map[level].end(),
                  image.rgb.begin() + 3 * (static_cast<std::ptrdiff_t>(y) * w + x));
      }
    }
    cv::Mat mat = as_mat(image);
    cv::rectangle(mat, cv::Point(left - 1, upper - 1), cv::Point(right, bottom), cv::Scalar(255, 255, 255), 1);
    const double scale = font_scale(image);
    for (const auto& [text, y] : {std::pair{pixels(top), upper}, std::pair{std::string("0"), bottom}}) {
      int baseline = 0;
      const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
      boxed_text(mat, text, std::max(3, left - size.width - 8), std::clamp(y + size.height / 2, size.height + 3, h - 3),
                 scale);
    }
  }
  return image;
}

void draw_label(RgbImage& image, const std::string& text) {
  check_image(image);
  cv::Mat mat = as_mat(image);
  const double scale = font_scale(image);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, scale, 1, &baseline);
  boxed_text(mat, text, 6, 6 + size.height, scale);
}

}  // namespace neuflow::flow
