#include "neuflow/flow/visualize.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "neuflow/flow/colorwheel.hpp"
#include "test_util.hpp"

namespace neuflow::flow {
namespace {

Rgb8 pixel(const RgbImage& img, int x, int y) {
  const std::size_t i =
      3 * (static_cast<std::size_t>(y) * static_cast<std::size_t>(img.width) + static_cast<std::size_t>(x));
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

TEST(ColorWheel, MatchesTheMiddleburyTable) {
  const auto& w = colorwheel();
  ASSERT_EQ(w.size(), 55u);
  // Segment starts: red, yellow, green, cyan, blue, magenta.
  EXPECT_EQ(w[0], (Rgb8{255, 0, 0}));
  EXPECT_EQ(w[15], (Rgb8{255, 255, 0}));
  EXPECT_EQ(w[21], (Rgb8{0, 255, 0}));
  EXPECT_EQ(w[25], (Rgb8{0, 255, 255}));
  EXPECT_EQ(w[36], (Rgb8{0, 0, 255}));
  EXPECT_EQ(w[49], (Rgb8{255, 0, 255}));
  // In-between entries use floor(255 * i / n), as colorcode.cpp and flow_vis do.
  EXPECT_EQ(w[1], (Rgb8{255, 17, 0}));
  EXPECT_EQ(w[14], (Rgb8{255, 238, 0}));
  EXPECT_EQ(w[16], (Rgb8{213, 255, 0}));
  EXPECT_EQ(w[23], (Rgb8{0, 255, 127}));
  EXPECT_EQ(w[27], (Rgb8{0, 209, 255}));
  EXPECT_EQ(w[40], (Rgb8{78, 0, 255}));
  EXPECT_EQ(w[54], (Rgb8{255, 0, 43}));
}

TEST(ColorWheel, DirectionsGetTheirUsualColours) {
  EXPECT_EQ(flow_color(1, 0), (Rgb8{255, 0, 0}));     // right: red (wheel index 0)
  EXPECT_EQ(flow_color(0, 1), (Rgb8{255, 229, 0}));   // down: yellow-orange, between 13 and 14
  EXPECT_EQ(flow_color(-1, 0), (Rgb8{0, 209, 255}));  // left: cyan-blue, index 27
  EXPECT_EQ(flow_color(0, -1), (Rgb8{88, 0, 255}));   // up: blue-violet, between 40 and 41
}

TEST(ColorWheel, SaturationGrowsWithMagnitudeAndOutOfRangeIsDimmed) {
  EXPECT_EQ(flow_color(0, 0), (Rgb8{255, 255, 255}));
  EXPECT_EQ(flow_color(0.5, 0), (Rgb8{255, 127, 127}));
  EXPECT_EQ(flow_color(2, 0), (Rgb8{191, 0, 0}));  // 0.75 * 255
  EXPECT_EQ(flow_color(std::nan(""), 0), (Rgb8{0, 0, 0}));
}

TEST(Visualize, ZeroFlowIsWhite) {
  const Visualization v = visualize_flow(FlowField(5, 4));
  EXPECT_EQ(v.max_flow, 0.0);
  ASSERT_EQ(v.image.rgb.size(), 5u * 4u * 3u);
  EXPECT_TRUE(std::all_of(v.image.rgb.begin(), v.image.rgb.end(), [](auto c) { return c == 255; }));
}

TEST(Visualize, PureRightFlowHasTheWheelsRed) {
  FlowField f(2, 1);
  f.u(0, 0) = 4.f;
  f.u(1, 0) = 2.f;
  const Visualization v = visualize_flow(f);
  EXPECT_EQ(v.max_flow, 4.0);
  EXPECT_EQ(pixel(v.image, 0, 0), colorwheel()[0]);
  EXPECT_EQ(pixel(v.image, 1, 0), (Rgb8{255, 127, 127}));
}

TEST(Visualize, LargestVectorIsFullySaturatedNotDimmed) {
  // An awkward direction whose normalized length could round above 1.
  FlowField f(3, 1);
  f.u(0, 0) = 0.1f;
  f.v(0, 0) = 0.7f;
  f.u(1, 0) = -0.03f;
  f.v(1, 0) = 0.01f;
  const Visualization v = visualize_flow(f);
  const Rgb8 c = pixel(v.image, 0, 0);
  EXPECT_EQ(*std::max_element(c.begin(), c.end()), 255) << "max pixel was dimmed";
  EXPECT_EQ(pixel(v.image, 2, 0), (Rgb8{255, 255, 255}));
}

TEST(Visualize, InvalidAndNonFinitePixelsAreBlackAndIgnoredForTheMaximum) {
  FlowField f(3, 1);
  f.u(0, 0) = 1000.f;  // invalid: must not set the scale
  f.u(1, 0) = 2.f;
  f.v(2, 0) = std::numeric_limits<float>::quiet_NaN();
  f.valid = {0, 1, 1};
  const Visualization v = visualize_flow(f);
  EXPECT_EQ(v.max_flow, 2.0);
  EXPECT_EQ(max_flow_magnitude(f), 2.0);
  EXPECT_EQ(pixel(v.image, 0, 0), (Rgb8{0, 0, 0}));
  EXPECT_EQ(pixel(v.image, 1, 0), (Rgb8{255, 0, 0}));
  EXPECT_EQ(pixel(v.image, 2, 0), (Rgb8{0, 0, 0}));
}

TEST(Visualize, FixedMaximum) {
  FlowField f(3, 1);
  f.u(0, 0) = 5.f;   // at the maximum: full red
  f.u(1, 0) = 10.f;  // beyond: dimmed red
  f.u(2, 0) = 2.5f;  // half
  VisualizeOptions options;
  options.max_flow = 5.0;
  const Visualization v = visualize_flow(f, options);
  EXPECT_EQ(v.max_flow, 5.0);
  EXPECT_EQ(pixel(v.image, 0, 0), (Rgb8{255, 0, 0}));
  EXPECT_EQ(pixel(v.image, 1, 0), (Rgb8{191, 0, 0}));
  EXPECT_EQ(pixel(v.image, 2, 0), (Rgb8{255, 127, 127}));
  options.max_flow = 0.0;
  EXPECT_THROW(visualize_flow(f, options), std::invalid_argument);
  options.max_flow = std::numeric_limits<double>::infinity();
  EXPECT_THROW(visualize_flow(f, options), std::invalid_argument);
}

TEST(Visualize, MatchesFlowColorOfTheNormalizedVector) {
  const FlowField f = test::make_field(16, 12);
  const Visualization v = visualize_flow(f);
  for (int y = 0; y < 12; y += 3) {
    for (int x = 0; x < 16; x += 5) {
      const Rgb8 expected =
          flow_color(static_cast<double>(f.u(x, y)) / v.max_flow, static_cast<double>(f.v(x, y)) / v.max_flow);
      const Rgb8 got = pixel(v.image, x, y);
      for (std::size_t c = 0; c < 3; ++c) EXPECT_NEAR(got[c], expected[c], 1) << x << "," << y;
    }
  }
}

TEST(Visualize, WritesAnRgbPng) {
  test::TempDir dir;
  RgbImage img{2, 1, {10, 20, 30, 40, 50, 60}};
  write_rgb_png(img, dir / "v.png");
  const cv::Mat m = cv::imread((dir / "v.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(m.type(), CV_8UC3);
  EXPECT_EQ(m.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));  // OpenCV reads BGR
  EXPECT_EQ(m.at<cv::Vec3b>(0, 1), cv::Vec3b(60, 50, 40));
  RgbImage bad{2, 2, {1, 2, 3}};
  EXPECT_THROW(write_rgb_png(bad, dir / "bad.png"), std::invalid_argument);
  EXPECT_THROW(write_rgb_png(img, dir / "missing" / "v.png"), FlowFileError);
}

}  // namespace
}  // namespace neuflow::flow
