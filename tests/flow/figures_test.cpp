// The pictures beyond the colour rendering: key, arrows, blend, error map, labels.
#include "neuflow/flow/figures.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "neuflow/flow/arrows.hpp"
#include "neuflow/flow/colorwheel.hpp"
#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::constant_field;

RgbImage filled(int w, int h, std::uint8_t value) {
  return {w, h, std::vector<std::uint8_t>(3 * static_cast<std::size_t>(w) * h, value)};
}

Rgb8 pixel(const RgbImage& img, int x, int y) {
  const std::size_t i = 3 * (static_cast<std::size_t>(y) * img.width + x);
  return {img.rgb[i], img.rgb[i + 1], img.rgb[i + 2]};
}

TEST(FlowKey, IsTheWheelWithItsRimAtMaxFlowInTheBottomRightCorner) {
  RgbImage image = filled(240, 160, 255);
  draw_key(image, 10.0);
  // Radius: a sixth of the shorter side (26), a quarter of it as margin (6).
  const int r = 26, cx = 240 - 6 - r, cy = 160 - 6 - r;
  EXPECT_EQ(pixel(image, cx, cy), flow_color(0, 0)) << "the centre is no motion: white";
  EXPECT_EQ(pixel(image, cx + 20, cy), flow_color(20.0 / r, 0)) << "right of the centre: rightward, red";
  EXPECT_EQ(pixel(image, cx, cy - 20), flow_color(0, -20.0 / r)) << "above the centre: upward";
  EXPECT_EQ(pixel(image, cx - 20, cy + 5), flow_color(-20.0 / r, 5.0 / r));
  EXPECT_EQ(pixel(image, 10, 10), (Rgb8{255, 255, 255})) << "the key stays in its corner";
  // The label "10.0 px", left of the disc, on its dark box.
  bool dark = false;
  for (int x = 0; x < cx - r; ++x) dark = dark || pixel(image, x, cy)[0] < 64;
  EXPECT_TRUE(dark) << "no label left of the key";
}

TEST(FlowArrows, CoverTheSegmentFromEachCellCentre) {
  const FlowField field = constant_field(4, 4, 8, 0);
  std::vector<std::uint8_t> coverage;
  arrow_coverage(field, 48, 48, 24, 1.0, std::numeric_limits<double>::infinity(), coverage);
  ASSERT_EQ(coverage.size(), 48u * 48u);
  // Anchors at 12 and 36; each arrow runs 8 px to the right.
  for (const int y : {12, 36}) {
    for (const int x0 : {12, 36}) {
      for (int x = x0 + 1; x < x0 + 7; ++x)
        EXPECT_GT(coverage[static_cast<std::size_t>(y) * 48 + x], 100) << x << "," << y;
      EXPECT_EQ(coverage[static_cast<std::size_t>(y) * 48 + x0 - 3], 0) << "nothing behind the anchor";
    }
  }
  EXPECT_EQ(coverage[24 * 48 + 24], 0) << "nothing between the rows of arrows";
  EXPECT_THROW(arrow_coverage(field, 48, 48, 0, 1.0, 1.0, coverage), std::invalid_argument);
}

TEST(FlowArrows, AutomaticScaleDrawsMaxFlowOneSpacingLong) {
  const ArrowScale s = automatic_arrow_scale(24, 12.0);
  EXPECT_DOUBLE_EQ(s.scale, 2.0);
  EXPECT_DOUBLE_EQ(s.max_length, 24.0);
}

TEST(FlowArrows, AreDrawnInTheirColour) {
  RgbImage image = filled(48, 48, 255);
  draw_arrows(image, constant_field(4, 4, 8, 0), 24, 1.0, 100.0, Rgb8{255, 0, 0});
  const Rgb8 on = pixel(image, 15, 12);  // on the shaft: red, but for the anti-aliasing's fraction
  EXPECT_EQ(on[0], 255);
  EXPECT_LT(on[1], 64);
  EXPECT_EQ(on[1], on[2]);
  EXPECT_EQ(pixel(image, 5, 5), (Rgb8{255, 255, 255}));
}

TEST(FlowBlend, WeighsTheRenderingOverThePicture) {
  const RgbImage under = filled(4, 3, 0), over = filled(4, 3, 200);
  EXPECT_EQ(pixel(blend(under, over, 0.5), 1, 1), (Rgb8{100, 100, 100}));
  EXPECT_EQ(blend(under, over, 0.0).rgb, under.rgb);
  EXPECT_EQ(blend(under, over, 1.0).rgb, over.rgb);
  EXPECT_THROW(blend(under, filled(5, 3, 0), 0.5), std::invalid_argument);
  EXPECT_THROW(blend(under, over, 1.5), std::invalid_argument);
}

TEST(FlowErrorMap, ColoursTheErrorByItsScaleAndGreysOutUnscoredPixels) {
  constexpr int w = 200, h = 120;
  FlowField truth = constant_field(w, h, 0, 0);
  truth.valid.assign(truth.pixel_count(), 1);
  truth.valid[static_cast<std::size_t>(60) * w + 10] = 0;
  FlowField predicted = constant_field(w, h, 0, 0);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w / 2; ++x) predicted.uv[2 * (static_cast<std::size_t>(y) * w + x)] = 2.0f;  // error 2 px
  }
  const RgbImage map = error_map(predicted, truth, 4.0);
  ASSERT_EQ(map.width, w);
  ASSERT_EQ(map.height, h);
  const Rgb8 half = pixel(map, 30, 70), none = pixel(map, 110, 70);
  EXPECT_EQ(pixel(map, 10, 60), (Rgb8{96, 96, 96})) << "a pixel the ground truth does not score: grey";
  EXPECT_EQ(pixel(map, 60, 90), half) << "one error, one colour";
  EXPECT_LT(none[0] + none[1] + none[2], 40) << "no error is dark";
  EXPECT_NE(none, pixel(map, 10, 60)) << "no error and not scored look alike";
  EXPECT_GT(half[0], 100) << "half the scale is the map's middle (inferno: crimson)";
  // The bar at the right edge: its top is the scale's end (bright yellow), its bottom dark.
  const int bar_x = w - std::max(3, w / 80) - 2;
  const int bottom = h - std::max(3, h / 10), upper = bottom - std::max(8, h * 3 / 5);
  const Rgb8 top = pixel(map, bar_x, upper + 1), low = pixel(map, bar_x, bottom - 2);
  EXPECT_GT(top[0] + top[1], 400) << "the bar's top";
  EXPECT_LT(low[0] + low[1] + low[2], 60) << "the bar's bottom";
  EXPECT_THROW(error_map(predicted, constant_field(w, h + 1, 0, 0)), std::invalid_argument);
}

TEST(FlowErrorMap, ANonFinitePredictionIsTheLargestError) {
  FlowField truth = constant_field(100, 80, 0, 0);
  FlowField predicted = constant_field(100, 80, 1, 0);
  predicted.uv[2 * (40 * 100 + 20)] = std::numeric_limits<float>::quiet_NaN();
  const RgbImage map = error_map(predicted, truth, 1.0);
  EXPECT_EQ(pixel(map, 20, 40), pixel(map, 30, 40)) << "NaN is drawn as the scale's end, like a 1 px error here";
}

TEST(FlowLabel, IsDrawnInTheTopLeftCorner) {
  RgbImage image = filled(200, 100, 255);
  draw_label(image, "prediction");
  int dark = 0;
  for (int y = 0; y < 30; ++y) {
    for (int x = 0; x < 100; ++x) dark += pixel(image, x, y)[0] < 64 ? 1 : 0;
  }
  EXPECT_GT(dark, 100) << "the label's box";
  EXPECT_EQ(pixel(image, 190, 90), (Rgb8{255, 255, 255}));
}

}  // namespace
}  // namespace neuflow::flow
