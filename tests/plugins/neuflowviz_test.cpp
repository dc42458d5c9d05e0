// neuflowviz on frames with a synthetic NeuflowFlowMeta: known colours of the Middlebury
// wheel, scaling of a grid smaller than the frame, overlay blending, arrows, passthrough.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "gst_test_util.hpp"
#include "neuflow/flow/colorwheel.hpp"

namespace neuflow::gst_test {
namespace {

using flow::flow_color;
using flow::Rgb8;

// Most tests look at the flow image alone (mode=flow); the default blends it over the video.
HarnessPtr make_viz(GstVideoFormat format, int width, int height, const char *mode = "flow") {
  HarnessPtr h(gst_harness_new("neuflowviz"));
  gst_util_set_object_arg(G_OBJECT(h->element), "mode", mode);
  gst_harness_set_src_caps_str(h.get(), caps_string(format, width, height).c_str());
  return h;
}

// A frame filled with `fill`, carrying a flow grid of uniform (u, v).
GstBuffer *frame_with_uniform_flow(GstVideoFormat format, int width, int height, std::uint8_t fill, int grid_width,
                                   int grid_height, float u, float v) {
  GstBuffer *buffer = make_frame(format, width, height, fill);
  add_flow(buffer, grid_width, grid_height,
           make_vectors(grid_width, grid_height,
                        [&](int, int) {
                          return std::pair{u, v};
                        }),
           width, height);
  return buffer;
}

Rgb8 rgb_at(GstBuffer *buffer, GstVideoFormat format, int width, int height, int x, int y) {
  GstVideoInfo info;
  gst_video_info_set_format(&info, format, static_cast<guint>(width), static_cast<guint>(height));
  const auto px = pixel_bytes(buffer, format, width, height, x, y);
  return {px.at(static_cast<std::size_t>(GST_VIDEO_INFO_COMP_POFFSET(&info, GST_VIDEO_COMP_R))),
          px.at(static_cast<std::size_t>(GST_VIDEO_INFO_COMP_POFFSET(&info, GST_VIDEO_COMP_G))),
          px.at(static_cast<std::size_t>(GST_VIDEO_INFO_COMP_POFFSET(&info, GST_VIDEO_COMP_B)))};
}

std::string to_string(const Rgb8 &c) {
  return "(" + std::to_string(c[0]) + ", " + std::to_string(c[1]) + ", " + std::to_string(c[2]) + ")";
}

// Every pixel of an RGB frame equals `expected`.
void expect_uniform(GstBuffer *buffer, int width, int height, const Rgb8 &expected) {
  for (int y = 0; y < height; ++y) {
    for (int x = 0; x < width; ++x) {
      const Rgb8 got = rgb_at(buffer, GST_VIDEO_FORMAT_RGB, width, height, x, y);
      ASSERT_EQ(got, expected) << "pixel (" << x << ", " << y << "): " << to_string(got) << " instead of "
                               << to_string(expected);
    }
  }
}

TEST(NeuflowViz, PropertiesHaveTheirDocumentedDefaults) {
  ElementPtr viz = owned(gst_element_factory_make("neuflowviz", nullptr));
  ASSERT_TRUE(viz) << "neuflowviz not found: is GST_PLUGIN_PATH the build directory?";
  gdouble max_flow = 0, alpha = 0, scale = -1;
  gboolean arrows = TRUE;
  guint spacing = 0, color = 0;
  gint mode = -1;
  g_object_get(viz.get(), "max-flow", &max_flow, "alpha", &alpha, "arrows", &arrows, "arrow-spacing", &spacing,
               "arrow-color", &color, "mode", &mode, "arrow-scale", &scale, nullptr);
  EXPECT_EQ(max_flow, 20.0);
  EXPECT_EQ(alpha, 0.6);
  EXPECT_FALSE(arrows);
  EXPECT_EQ(spacing, 24u);
  EXPECT_EQ(color, 0xff000000u);
  EXPECT_EQ(scale, 0.0);  // automatic
  EXPECT_EQ(mode, 0);     // overlay: what the README's live view expects
  gst_util_set_object_arg(G_OBJECT(viz.get()), "mode", "flow");
  g_object_get(viz.get(), "mode", &mode, nullptr);
  EXPECT_EQ(mode, 1);
}

TEST(NeuflowViz, ZeroFlowIsWhiteInFlowMode) {
  constexpr int w = 16, h = 12;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGBA, w, h);
  BufferPtr out(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGBA, w, h, 77, w, h, 0, 0)));
  ASSERT_TRUE(out);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const auto px = pixel_bytes(out.get(), GST_VIDEO_FORMAT_RGBA, w, h, x, y);
      ASSERT_EQ(px, (std::vector<std::uint8_t>{255, 255, 255, 77})) << "pixel (" << x << ", " << y << ")";
    }
  }
}

// Rightward flow at max-flow is the wheel's first colour, pure red, in every format; the
// alpha or padding byte is left alone.
struct FormatCase {
  GstVideoFormat format;
  std::vector<std::uint8_t> red_pixel;  // bytes of one pixel after drawing (fill 77 elsewhere)
};

class NeuflowVizFormats : public ::testing::TestWithParam<FormatCase> {};

TEST_P(NeuflowVizFormats, RightwardFlowAtMaxFlowIsTheWheelColourForAngleZero) {
  const FormatCase &c = GetParam();
  constexpr int w = 8, h = 6;
  ASSERT_EQ(flow::colorwheel()[0], (Rgb8{255, 0, 0}));
  ASSERT_EQ(flow_color(1.0, 0.0), flow::colorwheel()[0]);
  auto harness = make_viz(c.format, w, h);
  BufferPtr out(gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(c.format, w, h, 77, w, h, 20, 0)));
  ASSERT_TRUE(out);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      ASSERT_EQ(pixel_bytes(out.get(), c.format, w, h, x, y), c.red_pixel) << "pixel (" << x << ", " << y << ")";
    }
  }
}

INSTANTIATE_TEST_SUITE_P(PackedRgb, NeuflowVizFormats,
                         ::testing::Values(FormatCase{GST_VIDEO_FORMAT_RGB, {255, 0, 0}},
                                           FormatCase{GST_VIDEO_FORMAT_BGR, {0, 0, 255}},
                                           FormatCase{GST_VIDEO_FORMAT_RGBA, {255, 0, 0, 77}},
                                           FormatCase{GST_VIDEO_FORMAT_BGRA, {0, 0, 255, 77}},
                                           FormatCase{GST_VIDEO_FORMAT_RGBx, {255, 0, 0, 77}},
                                           FormatCase{GST_VIDEO_FORMAT_BGRx, {0, 0, 255, 77}},
                                           FormatCase{GST_VIDEO_FORMAT_ARGB, {77, 255, 0, 0}},
                                           FormatCase{GST_VIDEO_FORMAT_ABGR, {77, 0, 0, 255}},
                                           FormatCase{GST_VIDEO_FORMAT_xRGB, {77, 255, 0, 0}},
                                           FormatCase{GST_VIDEO_FORMAT_xBGR, {77, 0, 0, 255}}),
                         [](const ::testing::TestParamInfo<FormatCase> &param) {
                           return std::string(gst_video_format_to_string(param.param.format));
                         });

TEST(NeuflowViz, OtherDirectionsGetTheirWheelColours) {
  constexpr int w = 4, h = 4;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGB, w, h);
  const std::pair<float, float> directions[] = {{0, 20}, {-20, 0}, {0, -20}, {10, 0}, {40, 0}};
  for (const auto &[u, v] : directions) {
    BufferPtr out(
        gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, u, v)));
    ASSERT_TRUE(out);
    SCOPED_TRACE("flow (" + std::to_string(u) + ", " + std::to_string(v) + ")");
    expect_uniform(out.get(), w, h, flow_color(u / 20.0, v / 20.0));
  }
}

TEST(NeuflowViz, FrameWithoutFlowPassesThroughUnchangedAndUncopiedInOverlayMode) {
  constexpr int w = 8, h = 6;
  auto harness = make_viz(GST_VIDEO_FORMAT_BGRx, w, h, "overlay");
  for (int round = 0; round < 2; ++round) {
    // A buffer someone else also holds is not writable: an in-place transform would copy it.
    GstBuffer *in = make_frame(GST_VIDEO_FORMAT_BGRx, w, h, 77);
    BufferPtr keep(gst_buffer_ref(in));
    BufferPtr out(gst_harness_push_and_pull(harness.get(), in));
    ASSERT_TRUE(out);
    EXPECT_EQ(out.get(), keep.get()) << "round " << round;
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        ASSERT_EQ(pixel_bytes(out.get(), GST_VIDEO_FORMAT_BGRx, w, h, x, y), (std::vector<std::uint8_t>(4, 77)));
      }
    }
    // The next frame has flow again and is drawn.
    BufferPtr drawn(
        gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_BGRx, w, h, 77, w, h, 0, 0)));
    ASSERT_TRUE(drawn);
    EXPECT_NE(pixel_bytes(drawn.get(), GST_VIDEO_FORMAT_BGRx, w, h, 3, 3), (std::vector<std::uint8_t>(4, 77)));
  }
}

// The first frame of a stream has no flow yet: in flow mode it leaves as the zero-flow
// rendering (white), not as the camera picture, so a rendering never flashes the video.
TEST(NeuflowViz, FrameWithoutFlowIsZeroFlowWhiteInFlowMode) {
  constexpr int w = 8, h = 6;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGBA, w, h, "flow");
  GstBuffer *in = make_frame(GST_VIDEO_FORMAT_RGBA, w, h, 77);
  BufferPtr keep(gst_buffer_ref(in));  // not writable: the element must draw on a copy
  BufferPtr out(gst_harness_push_and_pull(harness.get(), in));
  ASSERT_TRUE(out);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      ASSERT_EQ(pixel_bytes(out.get(), GST_VIDEO_FORMAT_RGBA, w, h, x, y),
                (std::vector<std::uint8_t>{255, 255, 255, 77}));
      ASSERT_EQ(pixel_bytes(keep.get(), GST_VIDEO_FORMAT_RGBA, w, h, x, y), (std::vector<std::uint8_t>(4, 77)));
    }
  }
}

TEST(NeuflowViz, SmallerGridIsStretchedOverTheFrameWithVectorsInFramePixels) {
  // A 4x3 grid over a 16x12 frame: one grid pixel is 4 frame pixels, so a vector of 5 grid
  // pixels is 20 frame pixels, i.e. exactly max-flow.
  constexpr int w = 16, h = 12, gw = 4, gh = 3;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGB, w, h);
  GstBuffer *in = make_frame(GST_VIDEO_FORMAT_RGB, w, h, 0);
  add_flow(in, gw, gh, make_vectors(gw, gh, [](int x, int) { return std::pair{x < 2 ? 5.f : -5.f, 0.f}; }), w, h);
  BufferPtr out(gst_harness_push_and_pull(harness.get(), in));
  ASSERT_TRUE(out);
  for (int y = 0; y < h; ++y) {
    // Columns 0-5 sample only the left half of the grid, 10-15 only the right half.
    for (int x = 0; x <= 5; ++x) EXPECT_EQ(rgb_at(out.get(), GST_VIDEO_FORMAT_RGB, w, h, x, y), flow_color(1, 0));
    for (int x = 10; x < w; ++x) EXPECT_EQ(rgb_at(out.get(), GST_VIDEO_FORMAT_RGB, w, h, x, y), flow_color(-1, 0));
  }

  // Vertically: 3 grid pixels over 12 frame rows are 12 frame pixels.
  g_object_set(harness->element, "max-flow", 12.0, nullptr);
  BufferPtr down(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, gw, gh, 0, 3)));
  ASSERT_TRUE(down);
  expect_uniform(down.get(), w, h, flow_color(0, 1));
}

TEST(NeuflowViz, OverlayBlendsTheFlowColoursOverTheVideoWithAlpha) {
  constexpr int w = 6, h = 4;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGB, w, h);
  gst_util_set_object_arg(G_OBJECT(harness->element), "mode", "overlay");
  const std::pair<double, int> cases[] = {{0.5, 178}, {0.0, 100}, {1.0, 255}};  // white over grey 100
  for (const auto &[alpha, expected] : cases) {
    g_object_set(harness->element, "alpha", alpha, nullptr);
    BufferPtr out(
        gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 100, w, h, 0, 0)));
    ASSERT_TRUE(out);
    SCOPED_TRACE("alpha " + std::to_string(alpha));
    const auto e = static_cast<std::uint8_t>(expected);
    expect_uniform(out.get(), w, h, Rgb8{e, e, e});
  }
}

TEST(NeuflowViz, MaxFlowZeroNormalizesEachFrameByItsLargestVector) {
  constexpr int w = 4, h = 4;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGB, w, h);
  BufferPtr fixed(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 3, 0)));
  ASSERT_TRUE(fixed);
  expect_uniform(fixed.get(), w, h, flow_color(3.0 / 20.0, 0));

  g_object_set(harness->element, "max-flow", 0.0, nullptr);
  BufferPtr automatic(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 3, 0)));
  ASSERT_TRUE(automatic);
  expect_uniform(automatic.get(), w, h, flow_color(1, 0));

  // A motionless frame stays white rather than dividing by zero.
  BufferPtr still(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 0, 0)));
  ASSERT_TRUE(still);
  expect_uniform(still.get(), w, h, Rgb8{255, 255, 255});
}

// How far a pixel is from the flow colour underneath, 0 (untouched) to 255 (black on white).
int darkening(GstBuffer *out, int w, int h, int x, int y, const Rgb8 &background) {
  const Rgb8 got = rgb_at(out, GST_VIDEO_FORMAT_RGB, w, h, x, y);
  int most = 0;
  for (std::size_t c = 0; c < 3; ++c) most = std::max(most, std::abs(static_cast<int>(background[c]) - got[c]));
  return most;
}

TEST(NeuflowViz, ArrowsStartAtTheGridPointsAndShowTheScaledDisplacement) {
  constexpr int w = 32, h = 32;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGB, w, h);
  g_object_set(harness->element, "arrows", TRUE, "arrow-spacing", 16u, "arrow-scale", 1.0, nullptr);
  const Rgb8 background = flow_color(6.0 / 20.0, 0);
  BufferPtr out(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 6, 0)));
  ASSERT_TRUE(out);
  // At true length (arrow-scale 1) the arrows start at the cell centres (8, 8), (24, 8),
  // (8, 24), (24, 24) and run 6 px right; the anti-aliased shaft covers its pixels.
  for (int ay : {8, 24}) {
    for (int ax : {8, 24}) {
      for (int x = ax; x <= ax + 6; ++x)
        EXPECT_GT(darkening(out.get(), w, h, x, ay, background), 100) << x << "," << ay;
      EXPECT_EQ(darkening(out.get(), w, h, ax - 2, ay, background), 0);  // nothing behind the start
      if (ax + 8 < w) {
        EXPECT_EQ(darkening(out.get(), w, h, ax + 8, ay, background), 0);  // nothing past the tip
      }
    }
  }
  // Everything else is within the arrow heads' reach of the shafts.
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (std::abs(y - 8) > 3 && std::abs(y - 24) > 3) {
        ASSERT_EQ(darkening(out.get(), w, h, x, y, background), 0) << x << "," << y;
      }
    }
  }
  // Lines are anti-aliased: the heads' diagonals leave partly covered pixels.
  bool partial = false;
  for (int y = 4; y <= 12 && !partial; ++y) {
    for (int x = 8; x <= 16 && !partial; ++x) {
      const int d = darkening(out.get(), w, h, x, y, background);
      partial = d > 0 && d < 200;
    }
  }
  EXPECT_TRUE(partial) << "no partly covered pixel: the arrows are not anti-aliased";

  // Automatic scale: a vector of max-flow (20 px) is one spacing (16 px) long, so this one is
  // 6 * 16 / 20 = 4.8 px and the tip stops short of where the true-length arrow ended.
  g_object_set(harness->element, "arrow-scale", 0.0, nullptr);
  BufferPtr scaled(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 6, 0)));
  ASSERT_TRUE(scaled);
  EXPECT_GT(darkening(scaled.get(), w, h, 12, 8, background), 100);
  EXPECT_EQ(darkening(scaled.get(), w, h, 15, 8, background), 0);
  // A vector far beyond max-flow is drawn one spacing long instead of crossing the frame:
  // compared with the same frame drawn without arrows, nothing changes past the next anchor.
  const auto one_huge_vector = [] {
    GstBuffer *in = make_frame(GST_VIDEO_FORMAT_RGB, 48, 16, 0);
    add_flow(in, 3, 1,
             make_vectors(3, 1,
                          [](int x, int) {
                            return x == 0 ? std::pair{100.f, 0.f} : std::pair{0.f, 0.f};
                          }),
             48, 16);
    return in;
  };
  auto wide = make_viz(GST_VIDEO_FORMAT_RGB, 48, 16);
  BufferPtr plain(gst_harness_push_and_pull(wide.get(), one_huge_vector()));
  g_object_set(wide->element, "arrows", TRUE, "arrow-spacing", 16u, nullptr);
  BufferPtr with_arrow(gst_harness_push_and_pull(wide.get(), one_huge_vector()));
  ASSERT_TRUE(plain && with_arrow);
  EXPECT_NE(rgb_at(with_arrow.get(), GST_VIDEO_FORMAT_RGB, 48, 16, 20, 8),
            rgb_at(plain.get(), GST_VIDEO_FORMAT_RGB, 48, 16, 20, 8));
  for (int x = 28; x < 48; ++x) {
    if (x == 40) continue;  // the third cell's anchor
    EXPECT_EQ(rgb_at(with_arrow.get(), GST_VIDEO_FORMAT_RGB, 48, 16, x, 8),
              rgb_at(plain.get(), GST_VIDEO_FORMAT_RGB, 48, 16, x, 8))
        << "x " << x;
  }

  // A translucent white: blended with the flow colour underneath.
  g_object_set(harness->element, "arrow-scale", 1.0, "arrow-color", 0x80ffffffu, nullptr);
  BufferPtr translucent(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_RGB, w, h, 0, w, h, 6, 0)));
  ASSERT_TRUE(translucent);
  // On the shaft (nearly full coverage) the pixel is about half way to white.
  const Rgb8 got = rgb_at(translucent.get(), GST_VIDEO_FORMAT_RGB, w, h, 10, 8);
  for (std::size_t c = 0; c < 3; ++c) {
    const int half = (background[c] * (255 - 128) + 255 * 128 + 127) / 255;
    EXPECT_LE(got[c], half) << "channel " << c;
    EXPECT_GE(got[c], background[c] + (half - background[c]) * 8 / 10) << "channel " << c;
  }
}

TEST(NeuflowViz, HugeAndNonFiniteVectorsAreClippedNotFatal) {
  constexpr int w = 32, h = 24;
  auto harness = make_viz(GST_VIDEO_FORMAT_RGBx, w, h);
  g_object_set(harness->element, "arrows", TRUE, "arrow-spacing", 4u, nullptr);
  GstBuffer *in = make_frame(GST_VIDEO_FORMAT_RGBx, w, h, 0);
  add_flow(in, 4, 3,
           make_vectors(4, 3,
                        [](int x, int y) {
                          if (x == 0) return std::pair{1e9f, -1e9f};
                          if (x == 1) return std::pair{std::numeric_limits<float>::quiet_NaN(), 0.f};
                          return std::pair{-1e30f * static_cast<float>(y + 1), 3.f};
                        }),
           w, h);
  BufferPtr out(gst_harness_push_and_pull(harness.get(), in));
  ASSERT_TRUE(out);
}

// The pipeline people will write: negotiation through videoconvert on both sides, and the
// flow meta surviving a conversion in front of the visualizer.
// Plays a gst-launch description to its end: EOS, or the error's type.
GstMessageType play_to_end(const char *description) {
  ElementPtr pipeline = owned(gst_parse_launch(description, nullptr));
  if (!pipeline) return GST_MESSAGE_UNKNOWN;
  if (gst_element_set_state(pipeline.get(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) return GST_MESSAGE_ERROR;
  BusPtr bus(gst_element_get_bus(pipeline.get()));
  MessagePtr msg(gst_bus_timed_pop_filtered(bus.get(), 10 * GST_SECOND,
                                            static_cast<GstMessageType>(GST_MESSAGE_EOS | GST_MESSAGE_ERROR)));
  gst_element_set_state(pipeline.get(), GST_STATE_NULL);
  return msg ? GST_MESSAGE_TYPE(msg.get()) : GST_MESSAGE_UNKNOWN;
}

TEST(NeuflowViz, NegotiatesThroughVideoconvert) {
  EXPECT_EQ(play_to_end("videotestsrc num-buffers=5 ! video/x-raw,format=I420,width=64,height=48 ! videoconvert ! "
                        "neuflowviz arrows=true ! videoconvert ! fakesink"),
            GST_MESSAGE_EOS);
}

TEST(NeuflowViz, FlowMetaSurvivesVideoconvertInFront) {
  constexpr int w = 8, h = 6;
  HarnessPtr harness(gst_harness_new_parse("videoconvert ! video/x-raw,format=RGBA ! neuflowviz mode=flow"));
  gst_harness_set_src_caps_str(harness.get(), caps_string(GST_VIDEO_FORMAT_I420, w, h).c_str());
  BufferPtr out(
      gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(GST_VIDEO_FORMAT_I420, w, h, 128, w, h, 20, 0)));
  ASSERT_TRUE(out);
  EXPECT_EQ(pixel_bytes(out.get(), GST_VIDEO_FORMAT_RGBA, w, h, 2, 2), (std::vector<std::uint8_t>{255, 0, 0, 255}));
}

// What `neuflow` passes through besides RGB (GRAY8, I420, NV12, YUY2) links straight to
// neuflowviz: converted to RGB inside, drawn, and the flow meta still on the drawn frame.
class NeuflowVizConverted : public ::testing::TestWithParam<GstVideoFormat> {};

TEST_P(NeuflowVizConverted, IsConvertedToRgbAndDrawnWithItsMetaKept) {
  constexpr int w = 8, h = 6;
  const GstVideoFormat format = GetParam();
  auto harness = make_viz(format, w, h);
  BufferPtr out(gst_harness_push_and_pull(harness.get(), frame_with_uniform_flow(format, w, h, 128, w, h, 20, 0)));
  ASSERT_TRUE(out);
  CapsPtr caps(gst_pad_get_current_caps(harness->sinkpad));
  ASSERT_TRUE(caps);
  GstVideoInfo info;
  ASSERT_TRUE(gst_video_info_from_caps(&info, caps.get()));
  ASSERT_TRUE(GST_VIDEO_INFO_IS_RGB(&info)) << gst_video_format_to_string(GST_VIDEO_INFO_FORMAT(&info));
  expect_uniform(out.get(), w, h, Rgb8{255, 0, 0});  // RGB: the first drawable format
  EXPECT_NE(neuflow_buffer_get_flow_meta(out.get()), nullptr) << "the flow meta is lost on the converted frame";
}

TEST_P(NeuflowVizConverted, WithoutFlowInOverlayModeIsOnlyConverted) {
  constexpr int w = 8, h = 6;
  const GstVideoFormat format = GetParam();
  auto harness = make_viz(format, w, h, "overlay");
  BufferPtr out(gst_harness_push_and_pull(harness.get(), make_frame(format, w, h, 128)));
  ASSERT_TRUE(out);
  const Rgb8 got = rgb_at(out.get(), GST_VIDEO_FORMAT_RGB, w, h, 3, 3);
  // Y = U = V = 128 (or grey 128): a mid grey, whatever the matrix.
  for (const auto c : got) EXPECT_NEAR(c, 128, 12) << to_string(got);
}

INSTANTIATE_TEST_SUITE_P(NeuflowsOtherFormats, NeuflowVizConverted,
                         ::testing::Values(GST_VIDEO_FORMAT_GRAY8, GST_VIDEO_FORMAT_I420, GST_VIDEO_FORMAT_NV12,
                                           GST_VIDEO_FORMAT_YUY2),
                         [](const ::testing::TestParamInfo<GstVideoFormat> &param) {
                           return std::string(gst_video_format_to_string(param.param));
                         });

TEST(NeuflowViz, LinksAfterAYuvSourceWithoutVideoconvert) {
  EXPECT_EQ(play_to_end("videotestsrc num-buffers=3 ! video/x-raw,format=NV12,width=64,height=48 ! neuflowviz ! "
                        "fakesink"),
            GST_MESSAGE_EOS);
}

// A camera's YUV colorimetry is not carried over to the RGB side (nor sRGB to the YUV side), so
// fixed caps on either side still link.
TEST(NeuflowViz, ColorimetryDoesNotCrossTheConversion) {
  EXPECT_EQ(play_to_end("videotestsrc num-buffers=3 ! video/x-raw,format=I420,width=64,height=48,colorimetry=bt601 ! "
                        "neuflowviz ! video/x-raw,format=RGB,colorimetry=sRGB ! fakesink"),
            GST_MESSAGE_EOS);
}

TEST(NeuflowViz, RgbFramesAreStillDrawnInPlace) {
  constexpr int w = 8, h = 6;
  auto harness = make_viz(GST_VIDEO_FORMAT_BGRx, w, h);
  GstBuffer *in = frame_with_uniform_flow(GST_VIDEO_FORMAT_BGRx, w, h, 77, w, h, 20, 0);
  BufferPtr out(gst_harness_push_and_pull(harness.get(), in));
  ASSERT_TRUE(out);
  EXPECT_EQ(out.get(), in) << "a writable RGB frame was copied instead of drawn on";
  CapsPtr caps(gst_pad_get_current_caps(harness->sinkpad));
  GstVideoInfo info;
  ASSERT_TRUE(gst_video_info_from_caps(&info, caps.get()));
  EXPECT_EQ(GST_VIDEO_INFO_FORMAT(&info), GST_VIDEO_FORMAT_BGRx);
}

}  // namespace
}  // namespace neuflow::gst_test
