#include "png_codec.hpp"

#include <cstring>
#include <string>

#include <opencv2/imgcodecs.hpp>

#include "binary.hpp"
#include "file_io.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/limits.hpp"

namespace neuflow::flow::detail {

namespace {

using Kind = FlowFileError::Kind;

std::uint32_t load_be_u32(const std::byte* p) {
  std::uint32_t v = 0;
  for (int i = 0; i < 4; ++i) v = (v << 8) | std::to_integer<std::uint32_t>(p[i]);
  return v;
}

}  // namespace

const char* png_color_type_name(int color_type) {
  switch (color_type) {
    case 0: return "grayscale";
    case 2: return "RGB";
    case 3: return "palette";
    case 4: return "grayscale+alpha";
    case 6: return "RGBA";
    default: return "unknown colour type";
  }
}

PngHeader parse_png_header(std::span<const std::byte> bytes, const std::filesystem::path& path) {
  static constexpr unsigned char kSignature[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  // signature (8) + chunk length (4) + "IHDR" (4) + width, height (8) + depth, colour type (2)
  constexpr std::size_t kNeeded = 26;
  if (bytes.size() < 8 || std::memcmp(bytes.data(), kSignature, 8) != 0) {
    throw FlowFileError(Kind::malformed, path, "not a PNG file (wrong signature)");
  }
  if (bytes.size() < kNeeded || std::memcmp(bytes.data() + 12, "IHDR", 4) != 0) {
    throw FlowFileError(Kind::malformed, path, "truncated or corrupt PNG: no IHDR chunk");
  }
  PngHeader h;
  h.width = load_be_u32(bytes.data() + 16);
  h.height = load_be_u32(bytes.data() + 20);
  h.bit_depth = std::to_integer<int>(bytes[24]);
  h.color_type = std::to_integer<int>(bytes[25]);
  if (!flow_size_acceptable(h.width, h.height)) {
    throw FlowFileError(Kind::malformed, path,
                        "implausible PNG size " + std::to_string(h.width) + "x" +
                            std::to_string(h.height) + " (accepted: 1.." +
                            std::to_string(kMaxFlowSide) + " per side, at most " +
                            std::to_string(kMaxFlowPixels) + " pixels)");
  }
  return h;
}

cv::Mat decode_png(std::span<const std::byte> bytes, const std::filesystem::path& path) {
  cv::Mat image;
  try {
    // imdecode only reads the buffer; the const_cast is for the Mat wrapper's signature.
    const cv::Mat buffer(1, static_cast<int>(bytes.size()), CV_8UC1,
                         const_cast<std::byte*>(bytes.data()));
    image = cv::imdecode(buffer, cv::IMREAD_UNCHANGED);
  } catch (const cv::Exception& e) {
    throw FlowFileError(Kind::malformed, path, std::string("cannot decode PNG: ") + e.what());
  }
  if (image.empty()) throw FlowFileError(Kind::malformed, path, "cannot decode PNG (corrupt data?)");
  return image;
}

void write_png_atomically(const cv::Mat& image, const std::filesystem::path& path) {
  std::vector<uchar> encoded;
  try {
    if (!cv::imencode(".png", image, encoded)) {
      throw FlowFileError(Kind::write_failed, path, "PNG encoding failed");
    }
  } catch (const cv::Exception& e) {
    throw FlowFileError(Kind::write_failed, path, std::string("PNG encoding failed: ") + e.what());
  }
  write_file_atomically(path, std::as_bytes(std::span(encoded)));
}

}  // namespace neuflow::flow::detail
