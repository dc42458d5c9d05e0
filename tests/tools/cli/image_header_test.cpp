// An image's size from its header (tools/neuflow/common/image_header.*), which the flow, convert
// and eval commands check before decoding; and convert's frames refusing an image by it.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "common/exit_codes.hpp"
#include "common/image_header.hpp"
#include "convert/frames.hpp"
#include "convert/input_error.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::cli {
namespace {

std::vector<unsigned char> encoded(const char* extension, int width, int height) {
  cv::Mat image(height, width, CV_8UC3, cv::Scalar(10, 200, 30));
  std::vector<unsigned char> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes));
  return bytes;
}

void write(const std::filesystem::path& path, const std::vector<unsigned char>& bytes) {
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

TEST(ImageHeader, PngAndJpegSizesComeFromTheirHeaders) {
  const test::TempDir dir;
  write(dir / "a.png", encoded(".png", 37, 23));
  write(dir / "a.jpg", encoded(".jpg", 41, 19));
  const auto png = image_dimensions(dir / "a.png"), jpeg = image_dimensions(dir / "a.jpg");
  ASSERT_TRUE(png && jpeg);
  EXPECT_EQ(png->width, 37);
  EXPECT_EQ(png->height, 23);
  EXPECT_EQ(jpeg->width, 41);
  EXPECT_EQ(jpeg->height, 19);
}

// A JPEG whose frame header says 20000×20000 over 41×19 of data: the header is what is read.
TEST(ImageHeader, AJpegIsMeasuredByItsFrameHeaderNotItsData) {
  const test::TempDir dir;
  auto bytes = encoded(".jpg", 41, 19);
  bool patched = false;
  for (std::size_t i = 0; i + 8 < bytes.size() && !patched; ++i) {
    if (bytes[i] == 0xFF && bytes[i + 1] == 0xC0) {  // SOF0: length(2) precision(1) height(2) width(2)
      bytes[i + 5] = bytes[i + 7] = 20000 >> 8;
      bytes[i + 6] = bytes[i + 8] = 20000 & 0xFF;
      patched = true;
    }
  }
  ASSERT_TRUE(patched);
  write(dir / "huge.jpg", bytes);
  const auto dims = image_dimensions(dir / "huge.jpg");
  ASSERT_TRUE(dims);
  EXPECT_EQ(dims->width, 20000);
  EXPECT_EQ(dims->height, 20000);
}

// Other formats, broken headers and missing files give no size: the decoder then says what is
// wrong, as before.
TEST(ImageHeader, WhatItCannotReadHasNoSize) {
  const test::TempDir dir;
  write(dir / "a.bmp", encoded(".bmp", 8, 8));
  auto png = encoded(".png", 8, 8);
  png.resize(12);
  write(dir / "cut.png", png);
  write(dir / "text.png", {'h', 'e', 'l', 'l', 'o'});
  auto jpeg = encoded(".jpg", 8, 8);
  jpeg.resize(40);
  write(dir / "cut.jpg", jpeg);
  for (const char* name : {"a.bmp", "cut.png", "text.png", "cut.jpg", "absent.png"}) {
    EXPECT_FALSE(image_dimensions(dir / name)) << name;
  }
}

TEST(ImageHeader, ASizeTheCheckRefusesIsAnErrorNamingTheFileAndTheSize) {
  const test::TempDir dir;
  write(dir / "a.png", encoded(".png", 64, 48));
  const auto refuse_wide = [](int w, int) -> std::optional<std::string> {
    if (w > 32) return "wider than 32";
    return std::nullopt;
  };
  const auto problem = image_too_large(dir / "a.png", refuse_wide);
  ASSERT_TRUE(problem);
  EXPECT_EQ(*problem, (dir / "a.png").string() + ": its header says 64x48, not decoded: wider than 32");
  EXPECT_FALSE(image_too_large(dir / "a.png", [](int, int) { return std::optional<std::string>(); }));
}

// convert's frames check each image by its header before decoding it: a data error (65) naming it.
TEST(ImageHeader, ConvertRefusesAnImageBeforeDecodingIt) {
  const test::TempDir dir;
  write(dir / "a.png", encoded(".png", 64, 48));
  write(dir / "b.png", encoded(".png", 64, 48));
  InputSpec pair{InputKind::image_pair, {(dir / "a.png").string(), (dir / "b.png").string()}, "pair", "pair", {}};
  auto frames = open_frames(pair, [](int w, int h) -> std::optional<std::string> {
    return std::to_string(w) + "x" + std::to_string(h) + " is too large here";
  });
  try {
    frames->next();
    ADD_FAILURE() << "the image was decoded";
  } catch (const InputError& e) {
    EXPECT_EQ(e.exit_code, kExitDataError);
    EXPECT_NE(std::string(e.what()).find("its header says 64x48, not decoded: 64x48 is too large here"),
              std::string::npos)
        << e.what();
  }
  EXPECT_TRUE(open_frames(pair)->next()) << "without a check the image is read";
}

}  // namespace
}  // namespace neuflow::cli
