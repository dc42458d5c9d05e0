#include "neuflow/flow/kitti_png_format.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::expect_flow_error;
using Kind = FlowFileError::Kind;

// Values on the 1/64 grid survive the 16-bit encoding exactly.
FlowField grid_field(int w, int h) {
  FlowField f(w, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      f.u(x, y) = static_cast<float>(x * 37 - 200) / 64.f;
      f.v(x, y) = static_cast<float>(-y * 53 + 11) / 64.f;
    }
  }
  return f;
}

TEST(KittiPng, RoundTripOnTheQuantizationGridIsExact) {
  test::TempDir dir;
  const FlowField f = grid_field(21, 9);
  write_kitti_png(f, dir / "k.png");
  const FlowField g = read_kitti_png(dir / "k.png");
  ASSERT_EQ(g.width, 21);
  ASSERT_EQ(g.height, 9);
  EXPECT_EQ(g.uv, f.uv);
  // KITTI is sparse ground truth: the reader always provides a mask.
  ASSERT_TRUE(g.has_mask());
  EXPECT_EQ(std::count(g.valid.begin(), g.valid.end(), 0), 0);
}

TEST(KittiPng, MaskRoundTripsAndInvalidPixelsGetZero) {
  test::TempDir dir;
  FlowField f = grid_field(8, 8);
  f.valid.assign(f.pixel_count(), 1);
  f.valid[3] = 0;
  f.valid[60] = 0;
  f.u(5, 5) = std::numeric_limits<float>::quiet_NaN();  // non-finite: written invalid
  write_kitti_png(f, dir / "k.png");
  const FlowField g = read_kitti_png(dir / "k.png");
  auto expected_mask = f.valid;
  expected_mask[5 * 8 + 5] = 0;
  EXPECT_EQ(g.valid, expected_mask);
  EXPECT_EQ(g.u(3, 0), 0.f);
  EXPECT_EQ(g.v(3, 0), 0.f);
  EXPECT_EQ(g.u(1, 0), f.u(1, 0));
}

TEST(KittiPng, InvalidPixelsAreWrittenAllZeroLikeTheDevkit) {
  test::TempDir dir;
  FlowField f(2, 1);
  f.u(0, 0) = 1.f;
  f.v(0, 0) = -1.f;
  f.u(1, 0) = 7.f;
  f.valid = {1, 0};
  write_kitti_png(f, dir / "k.png");
  const cv::Mat m = cv::imread((dir / "k.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(m.type(), CV_16UC3);
  // OpenCV order B, G, R: valid flag, v, u.
  EXPECT_EQ(m.at<cv::Vec3w>(0, 0), cv::Vec3w(1, 32768 - 64, 32768 + 64));
  EXPECT_EQ(m.at<cv::Vec3w>(0, 1), cv::Vec3w(0, 0, 0));
}

TEST(KittiPng, ChannelOrderOfAFileWrittenByOtherTools) {
  test::TempDir dir;
  // A 16-bit image assembled by hand: B = valid, G = v, R = u.
  cv::Mat m(1, 2, CV_16UC3);
  m.at<cv::Vec3w>(0, 0) = cv::Vec3w(1, 32768 + 64, 32768 - 128);  // u = -2, v = 1
  m.at<cv::Vec3w>(0, 1) = cv::Vec3w(0, 40000, 40000);             // invalid
  ASSERT_TRUE(cv::imwrite((dir / "k.png").string(), m));
  const FlowField g = read_kitti_png(dir / "k.png");
  EXPECT_EQ(g.u(0, 0), -2.f);
  EXPECT_EQ(g.v(0, 0), 1.f);
  EXPECT_EQ(g.valid, (std::vector<std::uint8_t>{1, 0}));
  EXPECT_EQ(g.u(1, 0), 0.f);
}

TEST(KittiPng, WritingRoundsToNearestSixtyFourth) {
  test::TempDir dir;
  FlowField f(3, 1);
  f.u(0, 0) = 0.01f;    // 0.64/64 -> 1/64
  f.v(0, 0) = -0.007f;  // -0.448/64 -> 0
  f.u(1, 0) = 1.0f + 0.6f / 64.f;
  f.v(1, 0) = -3.3f;
  f.u(2, 0) = 100.123f;
  write_kitti_png(f, dir / "k.png");
  const FlowField g = read_kitti_png(dir / "k.png");
  EXPECT_EQ(g.u(0, 0), 1.f / 64.f);
  EXPECT_EQ(g.v(0, 0), 0.f);
  EXPECT_EQ(g.u(1, 0), 1.f + 1.f / 64.f);
  for (std::size_t i = 0; i < f.uv.size(); ++i) {
    EXPECT_LE(std::fabs(g.uv[i] - f.uv[i]), 0.5f / 64.f) << i;
  }
}

TEST(KittiPng, ValuesOutsideTheRangeAreClamped) {
  test::TempDir dir;
  FlowField f(2, 1);
  f.u(0, 0) = 1000.f;
  f.v(0, 0) = -1000.f;
  f.u(1, 0) = kKittiMaxFlow;
  f.v(1, 0) = kKittiMinFlow;
  write_kitti_png(f, dir / "k.png");
  const FlowField g = read_kitti_png(dir / "k.png");
  EXPECT_EQ(g.u(0, 0), kKittiMaxFlow);
  EXPECT_EQ(g.v(0, 0), kKittiMinFlow);
  EXPECT_EQ(g.u(1, 0), 511.984375f);
  EXPECT_EQ(g.v(1, 0), -512.f);
}

TEST(KittiPngErrors, EightBitPngIsNotAFlowField) {
  test::TempDir dir;
  cv::Mat m(4, 4, CV_8UC3, cv::Scalar(1, 2, 3));
  ASSERT_TRUE(cv::imwrite((dir / "img.png").string(), m));
  expect_flow_error([&] { read_kitti_png(dir / "img.png"); }, Kind::malformed, dir / "img.png",
                    "16 bits per channel, this one has 8");
}

TEST(KittiPngErrors, WrongChannelCount) {
  test::TempDir dir;
  cv::Mat gray(4, 4, CV_16UC1, cv::Scalar(5));
  ASSERT_TRUE(cv::imwrite((dir / "g.png").string(), gray));
  expect_flow_error([&] { read_kitti_png(dir / "g.png"); }, Kind::malformed, dir / "g.png",
                    "must be RGB (3 channels), this one is grayscale");
  cv::Mat rgba(4, 4, CV_16UC4, cv::Scalar(5, 5, 5, 5));
  ASSERT_TRUE(cv::imwrite((dir / "a.png").string(), rgba));
  expect_flow_error([&] { read_kitti_png(dir / "a.png"); }, Kind::malformed, dir / "a.png", "this one is RGBA");
}

TEST(KittiPngErrors, NotAPng) {
  test::TempDir dir;
  test::write_bytes(dir / "x.png", {'P', 'I', 'E', 'H', 0, 0, 0, 0, 0, 0, 0, 0});
  expect_flow_error([&] { read_kitti_png(dir / "x.png"); }, Kind::malformed, dir / "x.png", "not a PNG");
}

TEST(KittiPngErrors, TruncatedPng) {
  test::TempDir dir;
  write_kitti_png(grid_field(64, 64), dir / "k.png");
  auto bytes = test::read_bytes(dir / "k.png");
  bytes.resize(bytes.size() / 2);
  test::write_bytes(dir / "half.png", bytes);
  expect_flow_error([&] { read_kitti_png(dir / "half.png"); }, Kind::malformed, dir / "half.png", "decode");
  bytes.resize(20);
  test::write_bytes(dir / "head.png", bytes);
  expect_flow_error([&] { read_kitti_png(dir / "head.png"); }, Kind::malformed, dir / "head.png", "IHDR");
}

TEST(KittiPngErrors, AbsurdSizeInTheHeader) {
  test::TempDir dir;
  write_kitti_png(grid_field(4, 4), dir / "k.png");
  auto bytes = test::read_bytes(dir / "k.png");
  // IHDR width, big-endian at offset 16: claim 100000 pixels wide.
  bytes[16] = 0;
  bytes[17] = 0x01;
  bytes[18] = 0x86;
  bytes[19] = 0xa0;
  test::write_bytes(dir / "wide.png", bytes);
  expect_flow_error([&] { read_kitti_png(dir / "wide.png"); }, Kind::malformed, dir / "wide.png",
                    "implausible PNG size 100000x4");
}

TEST(KittiPngErrors, MissingFile) {
  test::TempDir dir;
  expect_flow_error([&] { read_kitti_png(dir / "none.png"); }, Kind::not_found, dir / "none.png", "no such file");
}

}  // namespace
}  // namespace neuflow::flow
