// The hand-off between the neuflow element's threads: order, newest-wins and back pressure,
// flushing that wakes every waiter, failures returned to the producer, draining, and
// producer and consumer threads stopped under load.
#include "frame_handoff.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

namespace neuflow::gst {
namespace {

using namespace std::chrono_literals;
using Handoff = FrameHandoff<int>;

int push_frame(Handoff& h, int v, Handoff::Policy p, std::vector<int>* dropped = nullptr) {
  return static_cast<int>(h.push_frame(v, p, dropped));
}
int push_other(Handoff& h, int v) { return static_cast<int>(h.push_other(v)); }
constexpr int kQueued = static_cast<int>(Handoff::Result::queued);

TEST(FrameHandoff, KeepsFramesAndOtherItemsInOrder) {
  Handoff h(4);
  ASSERT_EQ(push_other(h, 1), kQueued);
  ASSERT_EQ(push_frame(h, 2, Handoff::Policy::back_pressure), kQueued);
  ASSERT_EQ(push_other(h, 3), kQueued);
  ASSERT_EQ(push_frame(h, 4, Handoff::Policy::back_pressure), kQueued);
  for (int expected : {1, 2, 3, 4}) {
    const auto e = h.take();
    ASSERT_TRUE(e);
    EXPECT_EQ(e->value, expected);
    EXPECT_EQ(e->frame, expected % 2 == 0);
    h.done();
  }
}

TEST(FrameHandoff, NewestWinsReplacesWaitingFramesButKeepsEvents) {
  Handoff h(1);
  std::vector<int> dropped;
  push_frame(h, 10, Handoff::Policy::newest_wins, &dropped);
  push_other(h, 99);  // an event between frames stays
  push_frame(h, 11, Handoff::Policy::newest_wins, &dropped);
  push_frame(h, 12, Handoff::Policy::newest_wins, &dropped);
  EXPECT_EQ(dropped, (std::vector<int>{10, 11}));
  EXPECT_EQ(h.frames_waiting(), 1u);
  EXPECT_EQ(h.take()->value, 99);
  h.done();
  EXPECT_EQ(h.take()->value, 12);
  h.done();
}

TEST(FrameHandoff, BackPressureWaitsForRoomAndFlushingReleasesTheWaiter) {
  Handoff h(1);
  ASSERT_EQ(push_frame(h, 1, Handoff::Policy::back_pressure), kQueued);
  std::atomic<int> result{-1};
  std::thread producer([&] { result = push_frame(h, 2, Handoff::Policy::back_pressure); });
  std::this_thread::sleep_for(50ms);
  EXPECT_EQ(result.load(), -1) << "a second frame did not wait for room";
  ASSERT_EQ(h.take()->value, 1);  // room: the producer goes on
  producer.join();
  EXPECT_EQ(result.load(), kQueued);
  h.done();

  std::thread blocked([&] { result = push_frame(h, 3, Handoff::Policy::back_pressure); });
  std::this_thread::sleep_for(50ms);
  const auto discarded = h.start_flushing();
  blocked.join();
  EXPECT_EQ(result.load(), static_cast<int>(Handoff::Result::flushing));
  EXPECT_EQ(discarded, (std::vector<int>{2}));
}

TEST(FrameHandoff, AFailureIsReturnedToProducersUntilTheFlushStops) {
  Handoff h(1);
  push_frame(h, 1, Handoff::Policy::back_pressure);
  std::atomic<int> result{-1};
  std::thread producer([&] { result = push_frame(h, 2, Handoff::Policy::back_pressure); });
  std::this_thread::sleep_for(20ms);
  h.fail(-3);  // e.g. GST_FLOW_EOS from downstream
  producer.join();
  EXPECT_EQ(result.load(), static_cast<int>(Handoff::Result::failed));
  EXPECT_EQ(h.failure(), -3);
  EXPECT_FALSE(h.wait_drained()) << "a drain must not wait for a consumer that stopped on a failure";
  h.start_flushing();
  h.stop_flushing();
  EXPECT_EQ(h.failure(), 0);
  EXPECT_EQ(push_frame(h, 4, Handoff::Policy::back_pressure), kQueued);
}

TEST(FrameHandoff, WaitDrainedReturnsOnceTheConsumerIsDone) {
  Handoff h(2);
  push_frame(h, 1, Handoff::Policy::back_pressure);
  std::atomic<bool> drained{false};
  std::thread waiter([&] { drained = h.wait_drained(); });
  ASSERT_TRUE(h.take());
  std::this_thread::sleep_for(20ms);
  EXPECT_FALSE(drained.load()) << "drained while the consumer still held an item";
  h.done();
  waiter.join();
  EXPECT_TRUE(drained.load());
}

TEST(FrameHandoff, TakeWaitsAndReturnsNothingOnceFlushing) {
  Handoff h(1);
  std::atomic<bool> got_nothing{false};
  std::thread consumer([&] { got_nothing = !h.take().has_value(); });
  std::this_thread::sleep_for(20ms);
  h.start_flushing();
  consumer.join();
  EXPECT_TRUE(got_nothing.load());
  int v = 5;
  EXPECT_EQ(h.push_other(v), Handoff::Result::flushing);
  EXPECT_EQ(h.push_frame(v, Handoff::Policy::newest_wins), Handoff::Result::flushing);
}

// The element's three threads in miniature, stopped (flushed) while both sides run flat out,
// many times over: nothing is lost or handed out twice, and every thread returns.
TEST(FrameHandoff, StopsUnderLoadWithEveryItemAccountedFor) {
  for (int round = 0; round < 50; ++round) {
    Handoff input(2), output(1);
    std::atomic<long> produced{0}, dropped{0}, consumed{0}, discarded{0}, refused{0};
    std::atomic<bool> stop{false};
    std::thread producer([&] {
      std::vector<int> gone;
      for (int i = 0; !stop; ++i) {
        int v = i;
        const auto policy = i % 3 ? Handoff::Policy::back_pressure : Handoff::Policy::newest_wins;
        const auto r = input.push_frame(v, policy, &gone);
        ++produced;
        if (r != Handoff::Result::queued) ++refused;
        dropped += static_cast<long>(gone.size());
        gone.clear();
        if (r == Handoff::Result::flushing) break;
      }
    });
    std::thread worker([&] {
      while (auto e = input.take()) {
        int v = e->value;
        if (output.push_frame(v, Handoff::Policy::back_pressure) != Handoff::Result::queued) ++discarded;
        input.done();
      }
    });
    std::thread pusher([&] {
      while (auto e = output.take()) {
        ++consumed;
        output.done();
      }
    });
    std::this_thread::sleep_for(std::chrono::microseconds(200 + 50 * round));
    stop = true;
    const auto left_in = input.start_flushing();
    const auto left_out = output.start_flushing();
    producer.join();
    worker.join();
    pusher.join();
    EXPECT_EQ(produced.load(), dropped.load() + refused.load() + consumed.load() + discarded.load() +
                                   static_cast<long>(left_in.size() + left_out.size()))
        << "round " << round;
  }
}

}  // namespace
}  // namespace neuflow::gst
