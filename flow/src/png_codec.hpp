#pragma once
// PNG through libpng (not OpenCV's imgcodecs, which drags GDAL along and cannot be installed
// for another architecture beside the host's), with the header checks and error reporting the
// flow formats need (internal). Images are cv::Mat in OpenCV's channel order (BGR).
#include <cstdint>
#include <filesystem>
#include <span>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace neuflow::flow::detail {

// What a PNG's IHDR chunk says, read before decoding so that the errors can be precise and
// absurd sizes are refused without decoding.
struct PngHeader {
  std::int64_t width = 0;
  std::int64_t height = 0;
  int bit_depth = 0;
  int color_type = 0;  // 0 gray, 2 RGB, 3 palette, 4 gray+alpha, 6 RGBA
};

// Throws FlowFileError (malformed) if bytes do not start with a PNG signature and IHDR.
PngHeader parse_png_header(std::span<const std::byte> bytes, const std::filesystem::path& path);
const char* png_color_type_name(int color_type);

// Decodes as cv::imdecode(IMREAD_UNCHANGED) would: 8 or 16 bits as stored, BGR(A) order,
// palette and low-bit grey expanded. Throws FlowFileError.
cv::Mat decode_png(std::span<const std::byte> bytes, const std::filesystem::path& path);

// Encodes an 8- or 16-bit, 1/3/4-channel Mat (BGR order) and writes it atomically.
void write_png_atomically(const cv::Mat& image, const std::filesystem::path& path);

// Files above this are refused before they are read. Real flow PNGs are a few MB.
inline constexpr std::uint64_t kMaxPngFileBytes = std::uint64_t{1} << 30;

}  // namespace neuflow::flow::detail
