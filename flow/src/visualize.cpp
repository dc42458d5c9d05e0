#include "neuflow/flow/visualize.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <opencv2/core.hpp>

#include "field_check.hpp"
#include "neuflow/flow/limits.hpp"
#include "png_codec.hpp"
#include "wheel_color.hpp"

namespace neuflow::flow {

namespace {

// Magnitude of pixel i, or a negative value if the pixel is not to be drawn.
double magnitude(const FlowField& field, std::size_t i) {
  if (!field.valid.empty() && field.valid[i] == 0) return -1;
  const double u = field.uv[2 * i];
  const double v = field.uv[2 * i + 1];
  const double m = std::sqrt(u * u + v * v);
  return std::isfinite(m) ? m : -1;
}

}  // namespace

double max_flow_magnitude(const FlowField& field) {
  detail::check_field(field, "max_flow_magnitude");
  double max = 0;
  for (std::size_t i = 0; i < field.pixel_count(); ++i) max = std::max(max, magnitude(field, i));
  return max;
}

Visualization visualize_flow(const FlowField& field, const VisualizeOptions& options) {
  detail::check_field(field, "visualize_flow");
  Visualization out;
  if (options.max_flow) {
    if (!(std::isfinite(*options.max_flow) && *options.max_flow > 0)) {
      throw std::invalid_argument("visualize_flow: max_flow must be positive and finite, got " +
                                  std::to_string(*options.max_flow));
    }
    out.max_flow = *options.max_flow;
  } else {
    out.max_flow = max_flow_magnitude(field);
  }
  // A motionless field: any positive scale gives rad = 0, i.e. white, as the original does.
  const double scale = out.max_flow > 0 ? out.max_flow : 1.0;

  out.image.width = field.width;
  out.image.height = field.height;
  out.image.rgb.assign(3 * field.pixel_count(), 0);
  for (std::size_t i = 0; i < field.pixel_count(); ++i) {
    const double m = magnitude(field, i);
    if (m < 0) continue;  // invalid: black
    const Rgb8 c = detail::wheel_color(field.uv[2 * i], field.uv[2 * i + 1], m / scale);
    out.image.rgb[3 * i] = c[0];
    out.image.rgb[3 * i + 1] = c[1];
    out.image.rgb[3 * i + 2] = c[2];
  }
  return out;
}

void write_rgb_png(const RgbImage& image, const std::filesystem::path& path) {
  if (!flow_size_acceptable(image.width, image.height) ||
      image.rgb.size() != 3 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw std::invalid_argument("write_rgb_png " + path.string() + ": image of " + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + " has " + std::to_string(image.rgb.size()) + " bytes");
  }
  cv::Mat bgr(image.height, image.width, CV_8UC3);
  for (int y = 0; y < image.height; ++y) {
    auto* row = bgr.ptr<cv::Vec3b>(y);
    const std::uint8_t* src =
        image.rgb.data() + 3 * static_cast<std::size_t>(y) * static_cast<std::size_t>(image.width);
    for (int x = 0; x < image.width; ++x, src += 3) row[x] = cv::Vec3b(src[2], src[1], src[0]);
  }
  detail::write_png_atomically(bgr, path);
}

}  // namespace neuflow::flow
