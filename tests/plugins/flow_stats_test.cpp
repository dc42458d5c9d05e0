// The neuflow element's counters and latency estimate, without GStreamer.
#include <gtest/gtest.h>

#include "flow_stats.hpp"

namespace neuflow::gst {
namespace {

using namespace std::chrono_literals;

TEST(FlowStats, CountsFramesInOutFlowsAndDrops) {
  FlowStats s;
  const auto t0 = FlowStats::Clock::now();
  s.restart(t0);
  for (int i = 0; i < 5; ++i) s.frame_in();
  s.dropped(2);
  s.frame_out(false, 0);  // the first frame: no flow
  s.frame_out(true, 0.100);
  s.frame_out(true, 0.300);
  EXPECT_EQ(s.frames_in(), 5u);
  EXPECT_EQ(s.processed(), 3u);
  EXPECT_EQ(s.flows(), 2u);
  EXPECT_EQ(s.frames_dropped(), 2u);
  EXPECT_DOUBLE_EQ(s.mean_latency_ms(), 200.0);
  EXPECT_DOUBLE_EQ(s.processing_rate(t0 + 2s), 1.5);
  s.restart(t0 + 3s);
  EXPECT_EQ(s.frames_in(), 0u);
  EXPECT_EQ(s.flows(), 0u);
  EXPECT_EQ(s.processing_rate(t0 + 4s), 0.0);
}

TEST(FlowStats, LatencyIsAnnouncedWhenItAppearsAndWhenItMovesByAFifth) {
  FlowStats s;
  s.restart(FlowStats::Clock::now());
  EXPECT_FALSE(s.frame_out(false, 0));
  EXPECT_TRUE(s.frame_out(true, 1.0));  // a slow first flow (warm-up)
  EXPECT_DOUBLE_EQ(s.announced_latency(), 1.0);
  // Faster flows pull the moving average down: re-announced once it is more than 20% lower.
  EXPECT_FALSE(s.frame_out(true, 0.5));  // estimate 0.875
  EXPECT_TRUE(s.frame_out(true, 0.5));   // estimate 0.78125 < 0.8
  EXPECT_DOUBLE_EQ(s.announced_latency(), 0.78125);
  EXPECT_FALSE(s.frame_out(true, 0.78125));
}

TEST(FlowStats, MessagesFollowTheInterval) {
  FlowStats s;
  const auto t0 = FlowStats::Clock::now();
  s.restart(t0);
  EXPECT_FALSE(s.message_due(t0 + 999ms, 1000));
  EXPECT_TRUE(s.message_due(t0 + 1000ms, 1000));
  EXPECT_FALSE(s.message_due(t0 + 1500ms, 1000));
  EXPECT_TRUE(s.message_due(t0 + 2000ms, 1000));
  EXPECT_FALSE(s.message_due(t0 + 10s, 0));  // 0: no messages
}

}  // namespace
}  // namespace neuflow::gst
