// The session's settings: the limits and messages the element, the daemon and the CLI share.
#include <gtest/gtest.h>

#include "neuflow/model/session_settings.hpp"

namespace neuflow::model {
namespace {

TEST(SessionSettings, DefaultsAreUsable) {
  const SessionOptions defaults;
  EXPECT_EQ(defaults.iterations, (Iterations{1, 8}));
  EXPECT_EQ(defaults.network_order, ChannelOrder::rgb);
  EXPECT_FALSE(check_session_options(defaults));
}

TEST(SessionSettings, IterationLimitsAreInclusive) {
  EXPECT_FALSE(check_iterations_s16(SessionLimits::max_iterations_s16));
  EXPECT_FALSE(check_iterations_s8(SessionLimits::max_iterations_s8));
  EXPECT_FALSE(check_iterations_s8(0));
  EXPECT_EQ(check_iterations_s16(33).value_or(""), "expected a number of iterations 0 to 32, got 33");
  EXPECT_TRUE(check_iterations_s8(-1));
  EXPECT_EQ(check_session_options({.iterations = {1, 65}}).value_or(""),
            "iters-s8: expected a number of iterations 0 to 64, got 65");
}

TEST(SessionSettings, ModelSidesAreMultiplesOf16FromThirtyTwo) {
  EXPECT_FALSE(check_model_side(0));
  EXPECT_FALSE(check_model_side(32));
  EXPECT_FALSE(check_model_side(768));
  EXPECT_FALSE(check_model_side(SessionLimits::max_side));
  for (const int bad : {16, 100, -16, SessionLimits::max_side + 16}) {
    EXPECT_EQ(check_model_side(bad).value_or(""),
              "expected a multiple of 16, at least 32 (or 0 for the frames' own size), got " + std::to_string(bad));
  }
}

TEST(SessionSettings, ModelWidthAndHeightGoTogether) {
  EXPECT_FALSE(check_model_size(0, 0));
  EXPECT_FALSE(check_model_size(320, 256));
  EXPECT_TRUE(check_model_size(320, 0));
  EXPECT_EQ(check_model_size(100, 64).value_or("").rfind("model-width: ", 0), 0u);
  EXPECT_EQ(check_model_size(64, 100).value_or("").rfind("model-height: ", 0), 0u);
}

TEST(SessionSettings, ThreadsAreBounded) {
  EXPECT_FALSE(check_threads(0));
  EXPECT_FALSE(check_threads(SessionLimits::max_threads));
  EXPECT_EQ(check_session_options({.threads = -1}).value_or("").rfind("threads: ", 0), 0u);
}

TEST(SessionSettings, ModelSizeIsTheChosenOneOrThePaddedFrame) {
  EXPECT_EQ(model_size_for(1242, 375, SessionOptions{}), (ModelSize{1248, 384}));
  EXPECT_EQ(model_size_for(320, 256, SessionOptions{}), (ModelSize{320, 256}));
  EXPECT_EQ(model_size_for(1280, 720, {.model_width = 768, .model_height = 432}), (ModelSize{768, 432}));
}

TEST(SessionSettings, ChannelOrderNamesRoundTrip) {
  for (const auto order : {ChannelOrder::rgb, ChannelOrder::bgr}) {
    EXPECT_EQ(parse_channel_order(channel_order_name(order)), order);
  }
  EXPECT_FALSE(parse_channel_order("RGB"));
  EXPECT_FALSE(parse_channel_order(""));
}

}  // namespace
}  // namespace neuflow::model
