#include "neuflow/flow/kitti_png_format.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>

#include <opencv2/core.hpp>

#include "field_check.hpp"
#include "file_io.hpp"
#include "neuflow/flow/errors.hpp"
#include "png_codec.hpp"

namespace neuflow::flow {

namespace {

using Kind = FlowFileError::Kind;
constexpr float kZero = 32768.f;  // 2^15, the encoding of zero flow

std::uint16_t encode(float x) {
  const float scaled = std::round(x * kKittiScale + kZero);
  return static_cast<std::uint16_t>(std::clamp(scaled, 0.f, 65535.f));
}

}  // namespace

FlowField read_kitti_png(const std::filesystem::path& path) {
  const auto bytes = detail::read_whole_file(path, detail::kMaxPngFileBytes);
  const auto header = detail::parse_png_header(bytes, path);
  if (header.bit_depth != 16) {
    throw FlowFileError(Kind::malformed, path,
                        "a KITTI flow PNG must have 16 bits per channel, this one has " +
                            std::to_string(header.bit_depth) + " (an 8-bit PNG is an image, not a flow field)");
  }
  if (header.color_type != 2) {
    throw FlowFileError(Kind::malformed, path,
                        std::string("a KITTI flow PNG must be RGB (3 channels), this one is ") +
                            detail::png_color_type_name(header.color_type));
  }
  const cv::Mat image = detail::decode_png(bytes, path);
  if (image.type() != CV_16UC3 || image.cols != header.width || image.rows != header.height) {
    throw FlowFileError(Kind::malformed, path,
                        "decoded PNG is not a 16-bit 3-channel image of the size its header "
                        "states");
  }

  FlowField field(image.cols, image.rows);
  field.valid.assign(field.pixel_count(), 0);
  for (int y = 0; y < image.rows; ++y) {
    const auto* row = image.ptr<cv::Vec3w>(y);  // B, G, R
    for (int x = 0; x < image.cols; ++x) {
      const cv::Vec3w& p = row[x];
      if (p[0] == 0) continue;  // invalid: keep the zero placeholder
      field.u(x, y) = (static_cast<float>(p[2]) - kZero) / kKittiScale;
      field.v(x, y) = (static_cast<float>(p[1]) - kZero) / kKittiScale;
      field.valid[static_cast<std::size_t>(y) * static_cast<std::size_t>(image.cols) + static_cast<std::size_t>(x)] = 1;
    }
  }
  return field;
}

void write_kitti_png(const FlowField& field, const std::filesystem::path& path) {
  detail::check_field(field, "write_kitti_png " + path.string());
  cv::Mat image(field.height, field.width, CV_16UC3, cv::Scalar::all(0));
  for (int y = 0; y < field.height; ++y) {
    auto* row = image.ptr<cv::Vec3w>(y);
    for (int x = 0; x < field.width; ++x) {
      const float u = field.u(x, y);
      const float v = field.v(x, y);
      if (!field.is_valid(x, y) || !std::isfinite(u) || !std::isfinite(v)) continue;
      row[x] = cv::Vec3w(1, encode(v), encode(u));
    }
  }
  detail::write_png_atomically(image, path);
}

}  // namespace neuflow::flow
