#include "neuflow/flow/flo_format.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::append_f32;
using test::append_i32;
using test::expect_flow_error;
using Kind = FlowFileError::Kind;

std::vector<std::uint8_t> flo_header(std::int32_t w, std::int32_t h) {
  std::vector<std::uint8_t> b = {'P', 'I', 'E', 'H'};
  append_i32(b, w);
  append_i32(b, h);
  return b;
}

TEST(FloFormat, MagicBytesAreTheDocumentedFloat) {
  // "PIEH" read as a little-endian float is the magic of the Middlebury spec.
  EXPECT_EQ(std::bit_cast<std::uint32_t>(kFloMagic), 0x48454950u);
}

TEST(FloFormat, RoundTripIsBitExact) {
  test::TempDir dir;
  const FlowField f = test::make_field(13, 7);
  write_flo(f, dir / "a.flo");
  const FlowField g = read_flo(dir / "a.flo");
  EXPECT_EQ(g.width, 13);
  EXPECT_EQ(g.height, 7);
  EXPECT_EQ(g.uv, f.uv);
  EXPECT_FALSE(g.has_mask());
  EXPECT_EQ(std::filesystem::file_size(dir / "a.flo"), 12u + 8u * 13 * 7);
}

TEST(FloFormat, FileLayoutIsHeaderThenInterleavedRows) {
  test::TempDir dir;
  FlowField f(2, 1);
  f.u(0, 0) = 1.5f;
  f.v(0, 0) = -2.f;
  f.u(1, 0) = 3.f;
  f.v(1, 0) = 4.25f;
  write_flo(f, dir / "a.flo");
  auto expected = flo_header(2, 1);
  for (float x : {1.5f, -2.f, 3.f, 4.25f}) append_f32(expected, x);
  EXPECT_EQ(test::read_bytes(dir / "a.flo"), expected);
}

TEST(FloFormat, MaskRoundTripsThroughUnknownValues) {
  test::TempDir dir;
  const FlowField f = test::make_field(9, 5, /*with_mask=*/true);
  write_flo(f, dir / "m.flo");
  const FlowField g = read_flo(dir / "m.flo");
  ASSERT_TRUE(g.has_mask());
  EXPECT_EQ(g.valid, f.valid);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 9; ++x) {
      if (f.is_valid(x, y)) {
        EXPECT_EQ(g.u(x, y), f.u(x, y));
        EXPECT_EQ(g.v(x, y), f.v(x, y));
      } else {  // documented placeholder
        EXPECT_EQ(g.u(x, y), 0.f);
        EXPECT_EQ(g.v(x, y), 0.f);
      }
    }
  }
  // In the file, invalid pixels carry the Middlebury unknown value.
  const auto bytes = test::read_bytes(dir / "m.flo");
  float u0 = 0;
  std::memcpy(&u0, bytes.data() + 12, 4);
  EXPECT_EQ(u0, kFloUnknownValue);
}

TEST(FloFormat, NonFiniteValuesAreWrittenAsUnknown) {
  test::TempDir dir;
  FlowField f(3, 1);
  f.u(0, 0) = std::numeric_limits<float>::quiet_NaN();
  f.v(1, 0) = std::numeric_limits<float>::infinity();
  f.u(2, 0) = 2.f;
  write_flo(f, dir / "n.flo");
  const auto bytes = test::read_bytes(dir / "n.flo");
  for (int i = 0; i < 4; ++i) {
    float x = 0;
    std::memcpy(&x, bytes.data() + 12 + 4 * i, 4);
    EXPECT_EQ(x, kFloUnknownValue) << "value " << i;
  }
  const FlowField g = read_flo(dir / "n.flo");
  ASSERT_TRUE(g.has_mask());
  EXPECT_EQ(g.valid, (std::vector<std::uint8_t>{0, 0, 1}));
  EXPECT_EQ(g.u(2, 0), 2.f);
}

TEST(FloFormat, UnknownAndNonFiniteValuesReadAsInvalidWithZeroPlaceholder) {
  test::TempDir dir;
  auto b = flo_header(6, 1);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  for (float x : {1e10f, 0.f, 0.f, -2e9f, nan, 1.f, -inf, 1.f, 1e9f, -1e9f, 5.f, 6.f}) {
    append_f32(b, x);
  }
  test::write_bytes(dir / "u.flo", b);
  const FlowField g = read_flo(dir / "u.flo");
  ASSERT_TRUE(g.has_mask());
  // Exactly 1e9 is still a (silly but) known value: the convention is "greater than".
  EXPECT_EQ(g.valid, (std::vector<std::uint8_t>{0, 0, 0, 0, 1, 1}));
  for (int x = 0; x < 4; ++x) {
    EXPECT_EQ(g.u(x, 0), 0.f);
    EXPECT_EQ(g.v(x, 0), 0.f);
  }
  EXPECT_EQ(g.u(4, 0), 1e9f);
  EXPECT_EQ(g.v(5, 0), 6.f);
}

TEST(FloFormat, OpenCvReadsWhatWeWrite) {
  test::TempDir dir;
  const FlowField f = test::make_field(17, 11);
  write_flo(f, dir / "cv.flo");
  const cv::Mat m = cv::readOpticalFlow((dir / "cv.flo").string());
  ASSERT_FALSE(m.empty());
  ASSERT_EQ(m.type(), CV_32FC2);
  ASSERT_EQ(m.cols, 17);
  ASSERT_EQ(m.rows, 11);
  for (int y = 0; y < 11; ++y) {
    for (int x = 0; x < 17; ++x) {
      EXPECT_EQ(m.at<cv::Vec2f>(y, x)[0], f.u(x, y));
      EXPECT_EQ(m.at<cv::Vec2f>(y, x)[1], f.v(x, y));
    }
  }
}

TEST(FloFormat, WeReadWhatOpenCvWrites) {
  test::TempDir dir;
  cv::Mat m(5, 8, CV_32FC2);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 8; ++x) {
      m.at<cv::Vec2f>(y, x) = cv::Vec2f(0.5f * static_cast<float>(x), -0.25f * static_cast<float>(y));
    }
  }
  ASSERT_TRUE(cv::writeOpticalFlow((dir / "cv.flo").string(), m));
  const FlowField g = read_flo(dir / "cv.flo");
  ASSERT_EQ(g.width, 8);
  ASSERT_EQ(g.height, 5);
  for (int y = 0; y < 5; ++y) {
    for (int x = 0; x < 8; ++x) {
      EXPECT_EQ(g.u(x, y), m.at<cv::Vec2f>(y, x)[0]);
      EXPECT_EQ(g.v(x, y), m.at<cv::Vec2f>(y, x)[1]);
    }
  }
}

TEST(FloFormatErrors, MissingFile) {
  test::TempDir dir;
  expect_flow_error([&] { read_flo(dir / "none.flo"); }, Kind::not_found, dir / "none.flo", "no such file");
}

TEST(FloFormatErrors, DirectoryIsNotAFile) {
  test::TempDir dir;
  std::filesystem::create_directory(dir / "d.flo");
  expect_flow_error([&] { read_flo(dir / "d.flo"); }, Kind::not_found, dir / "d.flo", "directory");
}

TEST(FloFormatErrors, WrongMagic) {
  test::TempDir dir;
  auto b = flo_header(1, 1);
  b[0] = 'X';
  append_f32(b, 0.f);
  append_f32(b, 0.f);
  test::write_bytes(dir / "bad.flo", b);
  expect_flow_error([&] { read_flo(dir / "bad.flo"); }, Kind::malformed, dir / "bad.flo", "wrong magic");
}

TEST(FloFormatErrors, TruncatedHeader) {
  test::TempDir dir;
  test::write_bytes(dir / "t.flo", {'P', 'I', 'E', 'H', 1});
  expect_flow_error([&] { read_flo(dir / "t.flo"); }, Kind::malformed, dir / "t.flo", "truncated");
}

TEST(FloFormatErrors, EmptyFile) {
  test::TempDir dir;
  test::write_bytes(dir / "e.flo", {});
  expect_flow_error([&] { read_flo(dir / "e.flo"); }, Kind::malformed, dir / "e.flo", "truncated");
}

TEST(FloFormatErrors, TruncatedData) {
  test::TempDir dir;
  auto b = flo_header(4, 4);
  for (int i = 0; i < 31; ++i) append_f32(b, 1.f);  // one float short
  test::write_bytes(dir / "t.flo", b);
  expect_flow_error([&] { read_flo(dir / "t.flo"); }, Kind::malformed, dir / "t.flo", "truncated: the header says 4x4");
}

TEST(FloFormatErrors, TrailingDataMeansSizeMismatch) {
  test::TempDir dir;
  auto b = flo_header(2, 2);
  for (int i = 0; i < 10; ++i) append_f32(b, 1.f);
  test::write_bytes(dir / "t.flo", b);
  expect_flow_error([&] { read_flo(dir / "t.flo"); }, Kind::malformed, dir / "t.flo", "trailing data");
}

TEST(FloFormatErrors, AbsurdDimensionsAreRefusedBeforeAllocating) {
  test::TempDir dir;
  const std::pair<std::int32_t, std::int32_t> sizes[] = {
      {0, 5}, {5, 0}, {-1, 5}, {40000, 1}, {1, 40000}, {30000, 30000}, {-2147483647 - 1, -1}};
  for (const auto& [w, h] : sizes) {
    test::write_bytes(dir / "big.flo", flo_header(w, h));
    expect_flow_error([&] { read_flo(dir / "big.flo"); }, Kind::malformed, dir / "big.flo", "implausible size");
  }
  // The largest accepted size in a 12-byte file: caught by the size check, not by new[].
  test::write_bytes(dir / "big.flo", flo_header(16384, 16384));
  expect_flow_error([&] { read_flo(dir / "big.flo"); }, Kind::malformed, dir / "big.flo", "truncated");
}

TEST(FloFormatErrors, InconsistentFieldIsRejectedOnWrite) {
  test::TempDir dir;
  FlowField f(4, 4);
  f.uv.resize(3);
  EXPECT_THROW(write_flo(f, dir / "x.flo"), std::invalid_argument);
  FlowField g(4, 4);
  g.valid.assign(5, 1);
  EXPECT_THROW(write_flo(g, dir / "x.flo"), std::invalid_argument);
  EXPECT_THROW(write_flo(FlowField{}, dir / "x.flo"), std::invalid_argument);
  EXPECT_TRUE(dir.entries().empty());
}

}  // namespace
}  // namespace neuflow::flow
