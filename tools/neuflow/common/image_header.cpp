#include "common/image_header.hpp"

#include <jpeglib.h>
#include <png.h>

#include <csetjmp>
#include <cstdio>
#include <memory>

namespace neuflow::cli {

namespace {

using File = std::unique_ptr<std::FILE, int (*)(std::FILE*)>;

File open(const std::filesystem::path& path) { return {std::fopen(path.c_str(), "rb"), &std::fclose}; }

// libpng's messages stay unprinted: a header it cannot read is only "no size" here, and the
// decoder reports the file.
[[noreturn]] void png_fail(png_structp png, png_const_charp) { png_longjmp(png, 1); }
void png_quiet(png_structp, png_const_charp) {}

std::optional<ImageDimensions> png_dimensions(std::FILE* file) {
  png_structp png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, png_fail, png_quiet);
  if (png == nullptr) return std::nullopt;
  png_infop info = png_create_info_struct(png);
  std::optional<ImageDimensions> dims;
  // libpng reports a bad header by longjmp: nothing with a destructor lives in this frame.
  if (info != nullptr && setjmp(png_jmpbuf(png)) == 0) {
    png_init_io(png, file);
    png_read_info(png, info);
    dims = ImageDimensions{static_cast<int>(png_get_image_width(png, info)),
                           static_cast<int>(png_get_image_height(png, info))};
  }
  png_destroy_read_struct(&png, info != nullptr ? &info : nullptr, nullptr);
  return dims;
}

struct JpegErrors {
  jpeg_error_mgr manager;
  std::jmp_buf jump;
};

[[noreturn]] void jpeg_fail(j_common_ptr cinfo) {
  std::longjmp(reinterpret_cast<JpegErrors*>(cinfo->err)->jump, 1);  // NOLINT(cert-err52-cpp): libjpeg's way
}

void jpeg_quiet(j_common_ptr) {}

std::optional<ImageDimensions> jpeg_dimensions(std::FILE* file) {
  jpeg_decompress_struct cinfo{};
  JpegErrors errors{};
  cinfo.err = jpeg_std_error(&errors.manager);
  errors.manager.error_exit = jpeg_fail;
  errors.manager.output_message = jpeg_quiet;
  std::optional<ImageDimensions> dims;
  // As with libpng: the longjmp leaves only C structs behind.
  if (setjmp(errors.jump) == 0) {  // NOLINT(cert-err52-cpp)
    jpeg_create_decompress(&cinfo);
    jpeg_stdio_src(&cinfo, file);
    if (jpeg_read_header(&cinfo, TRUE) == JPEG_HEADER_OK) {
      dims = ImageDimensions{static_cast<int>(cinfo.image_width), static_cast<int>(cinfo.image_height)};
    }
  }
  jpeg_destroy_decompress(&cinfo);
  return dims;
}

}  // namespace

std::optional<ImageDimensions> image_dimensions(const std::filesystem::path& path) {
  const File file = open(path);
  if (!file) return std::nullopt;
  unsigned char magic[8] = {};
  const std::size_t n = std::fread(magic, 1, sizeof magic, file.get());
  std::rewind(file.get());
  if (n == sizeof magic && png_sig_cmp(magic, 0, sizeof magic) == 0) return png_dimensions(file.get());
  if (n >= 3 && magic[0] == 0xFF && magic[1] == 0xD8 && magic[2] == 0xFF) return jpeg_dimensions(file.get());
  return std::nullopt;
}

std::optional<std::string> image_too_large(const std::filesystem::path& path, const FrameSizeCheck& check) {
  const auto dims = image_dimensions(path);
  if (!dims) return std::nullopt;
  auto problem = check(dims->width, dims->height);
  if (!problem) return std::nullopt;
  return path.string() + ": its header says " + std::to_string(dims->width) + "x" + std::to_string(dims->height) +
         ", not decoded: " + *problem;
}

}  // namespace neuflow::cli
