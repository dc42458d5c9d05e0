#include "png_codec.hpp"

#include <png.h>

#include <bit>
#include <csetjmp>
#include <cstring>
#include <new>
#include <string>
#include <vector>

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
                        "implausible PNG size " + std::to_string(h.width) + "x" + std::to_string(h.height) +
                            " (accepted: 1.." + std::to_string(kMaxFlowSide) + " per side, at most " +
                            std::to_string(kMaxFlowPixels) + " pixels)");
  }
  return h;
}

namespace {

// libpng reports errors through longjmp; these carry its message back. No exception crosses
// libpng's C frames.
void record_error(png_structp png, png_const_charp message) {
  *static_cast<std::string*>(png_get_error_ptr(png)) = message ? message : "unknown libpng error";
  png_longjmp(png, 1);
}
void ignore_warning(png_structp, png_const_charp) {}

struct MemoryReader {
  std::span<const std::byte> bytes;
  std::size_t offset = 0;
};

void read_from_memory(png_structp png, png_bytep out, png_size_t length) {
  auto* reader = static_cast<MemoryReader*>(png_get_io_ptr(png));
  if (length > reader->bytes.size() - reader->offset) png_error(png, "truncated PNG data");
  std::memcpy(out, reader->bytes.data() + reader->offset, length);
  reader->offset += length;
}

void write_to_memory(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
  try {
    out->insert(out->end(), data, data + length);
  } catch (const std::bad_alloc&) {
    png_error(png, "out of memory");
  }
}
void flush_nothing(png_structp) {}

// PNG stores 16-bit samples big-endian; cv::Mat holds them in the host's order.
constexpr bool kSwap16 = std::endian::native == std::endian::little;

// Runs `steps` (libpng calls) with libpng's error jump armed: false when libpng gave up. The
// jump lands here, so the caller's variables are untouched by it, and `steps` creates nothing
// that needs destroying.
template <typename Steps>
bool run_libpng(png_structp png, Steps&& steps) {
  if (setjmp(png_jmpbuf(png))) return false;
  steps();
  return true;
}

}  // namespace

// libpng with the transforms that give what cv::imdecode(IMREAD_UNCHANGED) gives: palette and
// low-bit grey expanded, transparency as alpha, grey+alpha as BGRA, 16 bits kept, BGR order.
cv::Mat decode_png(std::span<const std::byte> bytes, const std::filesystem::path& path) {
  std::string error;
  MemoryReader reader{bytes, 0};
  cv::Mat image;
  std::vector<png_bytep> rows;
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, &error, record_error, ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw FlowFileError(Kind::malformed, path, "cannot decode PNG: out of memory");
  }
  const bool decoded = run_libpng(png, [&] {
    png_set_read_fn(png, &reader, read_from_memory);
    png_read_info(png, info);
    const int color = png_get_color_type(png, info);
    const int depth = png_get_bit_depth(png, info);
    if (color == PNG_COLOR_TYPE_PALETTE) png_set_palette_to_rgb(png);
    if (color == PNG_COLOR_TYPE_GRAY && depth < 8) png_set_expand_gray_1_2_4_to_8(png);
    if (png_get_valid(png, info, PNG_INFO_tRNS)) png_set_tRNS_to_alpha(png);
    if (color == PNG_COLOR_TYPE_GRAY_ALPHA) png_set_gray_to_rgb(png);
    if (depth == 16 && kSwap16) png_set_swap(png);
    png_set_bgr(png);
    png_read_update_info(png, info);
    const auto width = static_cast<int>(png_get_image_width(png, info));
    const auto height = static_cast<int>(png_get_image_height(png, info));
    const int channels = png_get_channels(png, info);
    const int out_depth = png_get_bit_depth(png, info) == 16 ? CV_16U : CV_8U;
    image.create(height, width, CV_MAKETYPE(out_depth, channels));
    rows.resize(static_cast<std::size_t>(height));
    for (int y = 0; y < height; ++y) rows[static_cast<std::size_t>(y)] = image.ptr(y);
    png_read_image(png, rows.data());
    png_read_end(png, nullptr);
  });
  if (!decoded) {
    png_destroy_read_struct(&png, &info, nullptr);
    throw FlowFileError(Kind::malformed, path, "cannot decode PNG: " + error);
  }
  png_destroy_read_struct(&png, &info, nullptr);
  return image;
}

void write_png_atomically(const cv::Mat& image, const std::filesystem::path& path) {
  const int depth = image.depth() == CV_16U ? 16 : 8;
  const int channels = image.channels();
  if ((image.depth() != CV_8U && image.depth() != CV_16U) || (channels != 1 && channels != 3 && channels != 4)) {
    throw FlowFileError(Kind::write_failed, path, "PNG encoding failed: unsupported image type");
  }
  std::string error;
  std::vector<unsigned char> encoded;
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y) rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(image.ptr(y));
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, record_error, ignore_warning);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!png || !info) {
    png_destroy_write_struct(&png, &info);
    throw FlowFileError(Kind::write_failed, path, "PNG encoding failed: out of memory");
  }
  const bool written = run_libpng(png, [&] {
    png_set_write_fn(png, &encoded, write_to_memory, flush_nothing);
    // zlib level 1, as OpenCV's imwrite: flows are written as fast as they arrive.
    png_set_compression_level(png, 1);
    const int color = channels == 1 ? PNG_COLOR_TYPE_GRAY : channels == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGBA;
    png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols), static_cast<png_uint_32>(image.rows), depth, color,
                 PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_write_info(png, info);
    if (channels > 1) png_set_bgr(png);
    if (depth == 16 && kSwap16) png_set_swap(png);
    png_write_image(png, rows.data());
    png_write_end(png, nullptr);
  });
  if (!written) {
    png_destroy_write_struct(&png, &info);
    throw FlowFileError(Kind::write_failed, path, "PNG encoding failed: " + error);
  }
  png_destroy_write_struct(&png, &info);
  write_file_atomically(path, std::as_bytes(std::span(encoded)));
}

}  // namespace neuflow::flow::detail
