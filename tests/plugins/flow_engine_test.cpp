// The `neuflow` element's engine without a pipeline: frames in through chain(), results out
// through a recording Downstream, on the CPU with the fixture checkpoint at a small size. What
// an element relies on: every frame out in order with the session's own flow, a flush that
// restarts the stream, a downstream failure that reaches upstream, and stopping (or destroying)
// a busy engine that returns and releases every buffer.
#include "flow_engine.hpp"

#include <gst/gst.h>
#include <gst/video/video.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "neuflow/gst/flow_meta.h"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "support/fixtures.hpp"

namespace neuflow::gst {
namespace {

constexpr int kWidth = 64, kHeight = 48;

// Counts buffers made and finalized, so a test can tell that none was kept or lost.
struct BufferCounter {
  std::atomic<int> made{0};
  std::atomic<int> freed{0};
};

void count_free(gpointer counter, GstMiniObject* /*buffer*/) { ++static_cast<BufferCounter*>(counter)->freed; }

GstBuffer* frame(int index, BufferCounter& counter) {
  const gsize size = static_cast<gsize>(kWidth) * kHeight * 3;
  GstBuffer* buffer = gst_buffer_new_allocate(nullptr, size, nullptr);
  GstMapInfo map;
  gst_buffer_map(buffer, &map, GST_MAP_WRITE);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      guint8* p = map.data + (static_cast<std::size_t>(y) * kWidth + x) * 3;
      p[0] = static_cast<guint8>((x + 2 * index) * 5);
      p[1] = static_cast<guint8>(y * 7 + index);
      p[2] = static_cast<guint8>((x + y + index) * 3);
    }
  }
  gst_buffer_unmap(buffer, &map);
  GST_BUFFER_PTS(buffer) = static_cast<GstClockTime>(index) * GST_SECOND / 30;
  GST_BUFFER_DURATION(buffer) = GST_SECOND / 30;
  ++counter.made;
  gst_mini_object_weak_ref(GST_MINI_OBJECT(buffer), count_free, &counter);
  return buffer;
}

GstEvent* caps_event() {
  GstCaps* caps = gst_caps_new_simple("video/x-raw", "format", G_TYPE_STRING, "RGB", "width", G_TYPE_INT, kWidth,
                                      "height", G_TYPE_INT, kHeight, "framerate", GST_TYPE_FRACTION, 30, 1, nullptr);
  GstEvent* event = gst_event_new_caps(caps);
  gst_caps_unref(caps);
  return event;
}

// What leaves the engine, in order; a push can be made slow or made to fail.
class RecordingDownstream : public Downstream {
 public:
  ~RecordingDownstream() override { clear(); }

  GstFlowReturn push(GstBuffer* buffer) override {
    if (delay.count() > 0) std::this_thread::sleep_for(delay);
    const std::lock_guard lock(mutex_);
    if (fail_at >= 0 && static_cast<int>(buffers_.size()) == fail_at) {
      gst_buffer_unref(buffer);
      return GST_FLOW_ERROR;
    }
    buffers_.push_back(buffer);
    changed_.notify_all();
    return GST_FLOW_OK;
  }
  bool push_event(GstEvent* event) override {
    const std::lock_guard lock(mutex_);
    if (GST_EVENT_TYPE(event) == GST_EVENT_EOS) eos_ = true;
    gst_event_unref(event);
    changed_.notify_all();
    return true;
  }

  bool wait_for(int buffers, std::chrono::seconds timeout = std::chrono::seconds(120)) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return static_cast<int>(buffers_.size()) >= buffers; });
  }
  bool wait_for_eos(std::chrono::seconds timeout = std::chrono::seconds(120)) {
    std::unique_lock lock(mutex_);
    return changed_.wait_for(lock, timeout, [&] { return eos_; });
  }
  std::vector<GstBuffer*> buffers() {
    const std::lock_guard lock(mutex_);
    return buffers_;
  }
  int size() {
    const std::lock_guard lock(mutex_);
    return static_cast<int>(buffers_.size());
  }
  void clear() {
    const std::lock_guard lock(mutex_);
    for (GstBuffer* b : buffers_) gst_buffer_unref(b);
    buffers_.clear();
  }

  std::chrono::milliseconds delay{0};
  int fail_at = -1;  // the index of the buffer whose push fails

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<GstBuffer*> buffers_;
  bool eos_ = false;
};

class FlowEngineTest : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
    model_ = model::FlowModel::load_shared(path.string());
    options_.backend = model::Backend::cpu;
    options_.threads = 1;  // the other core runs the test's producer
    options_.iterations = {1, 2};
    element_ = GST_ELEMENT(gst_object_ref_sink(gst_bin_new("engine-owner")));
    bus_ = gst_bus_new();
    gst_element_set_bus(element_, bus_);
  }
  void TearDown() override {
    engine_.reset();
    downstream_.clear();
    if (element_) gst_object_unref(element_);
    if (bus_) gst_object_unref(bus_);
  }

  FlowEngine& make_engine(model::Behaviour behaviour) {
    engine_ = std::make_unique<FlowEngine>(element_, downstream_, [behaviour] {
      return FlowEngine::Settings{behaviour, 0};
    });
    engine_->open(model_, options_);
    return *engine_;
  }

  // Starts the stream as a pad would see it: stream-start, caps, segment.
  void begin_stream(FlowEngine& engine) {
    ASSERT_TRUE(engine.start());
    ASSERT_TRUE(engine.queue_event(gst_event_new_stream_start("engine-test")));
    ASSERT_TRUE(engine.queue_event(caps_event()));
    GstSegment segment;
    gst_segment_init(&segment, GST_FORMAT_TIME);
    ASSERT_TRUE(engine.queue_event(gst_event_new_segment(&segment)));
  }

  bool error_posted() {
    GstMessage* message = gst_bus_pop_filtered(bus_, GST_MESSAGE_ERROR);
    if (!message) return false;
    gst_message_unref(message);
    return true;
  }

  static bool not_live() { return false; }

  std::shared_ptr<const model::FlowModel> model_;
  model::SessionOptions options_;
  GstElement* element_ = nullptr;
  GstBus* bus_ = nullptr;
  BufferCounter counter_;
  RecordingDownstream downstream_;
  std::unique_ptr<FlowEngine> engine_;
};

TEST_F(FlowEngineTest, EveryPairDeliversEveryFrameInOrderWithTheSessionsFlow) {
  FlowEngine& engine = make_engine(model::Behaviour::every_pair);
  begin_stream(engine);
  constexpr int kFrames = 4;
  for (int i = 0; i < kFrames; ++i) ASSERT_EQ(engine.chain(frame(i, counter_), not_live), GST_FLOW_OK);
  ASSERT_TRUE(engine.queue_event(gst_event_new_eos()));
  ASSERT_TRUE(downstream_.wait_for_eos());
  ASSERT_TRUE(engine.drain());

  const std::vector<GstBuffer*> out = downstream_.buffers();
  ASSERT_EQ(static_cast<int>(out.size()), kFrames);
  model::FlowSession reference(model_, options_);
  for (int i = 0; i < kFrames; ++i) {
    EXPECT_EQ(GST_BUFFER_PTS(out[i]), static_cast<GstClockTime>(i) * GST_SECOND / 30) << "frame " << i;
    GstMapInfo map;
    ASSERT_TRUE(gst_buffer_map(out[i], &map, GST_MAP_READ));
    const auto expected = reference.push(model::ImageView{map.data, kWidth, kHeight, kWidth * 3});
    gst_buffer_unmap(out[i], &map);
    const NeuflowFlowMeta* meta = neuflow_buffer_get_flow_meta(out[i]);
    if (i == 0) {
      EXPECT_EQ(meta, nullptr) << "the first frame of a stream leaves without flow";
      continue;
    }
    ASSERT_NE(meta, nullptr) << "frame " << i;
    ASSERT_TRUE(expected);
    ASSERT_EQ(meta->width, static_cast<guint>(kWidth));
    ASSERT_EQ(meta->height, static_cast<guint>(kHeight));
    const gfloat* uv = neuflow_flow_meta_get_vectors(meta);
    float max_diff = 0;
    for (std::size_t k = 0; k < expected->uv.size(); ++k)
      max_diff = std::max(max_diff, std::abs(uv[k] - expected->uv[k]));
    EXPECT_EQ(max_diff, 0.f) << "frame " << i << ": the engine's flow is not the session's";
  }
  const FlowStats stats = engine.stats();
  EXPECT_EQ(stats.frames_in(), static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(stats.processed(), static_cast<std::uint64_t>(kFrames));
  EXPECT_EQ(stats.flows(), static_cast<std::uint64_t>(kFrames - 1));
  EXPECT_FALSE(error_posted());
}

// A producer feeds frames as fast as chain() takes them while downstream is slow; stop() in the
// middle returns, the producer's next chain() says FLUSHING, and no buffer is left anywhere.
TEST_F(FlowEngineTest, StopUnderLoadReturnsAndReleasesEveryBuffer) {
  downstream_.delay = std::chrono::milliseconds(20);
  FlowEngine& engine = make_engine(model::Behaviour::live);
  begin_stream(engine);
  std::atomic<bool> flushing{false};
  std::thread producer([&] {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (int i = 0; std::chrono::steady_clock::now() < deadline; ++i) {
      if (engine.chain(frame(i, counter_), not_live) == GST_FLOW_FLUSHING) {
        flushing = true;
        return;
      }
    }
  });
  ASSERT_TRUE(downstream_.wait_for(3));
  engine.stop();
  producer.join();
  EXPECT_TRUE(flushing) << "chain() went on accepting frames after stop()";
  EXPECT_GT(engine.stats().frames_dropped(), 0u) << "live: frames waiting behind a busy worker are dropped";
  engine_.reset();
  downstream_.clear();
  EXPECT_EQ(counter_.freed.load(), counter_.made.load()) << "a buffer was kept by the engine";
}

// Destroying an engine whose tasks run, with frames waiting and in flight, joins them.
TEST_F(FlowEngineTest, DestroyingARunningEngineStopsItsTasks) {
  downstream_.delay = std::chrono::milliseconds(10);
  FlowEngine& engine = make_engine(model::Behaviour::every_pair);
  begin_stream(engine);
  std::thread producer([&] {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
    for (int i = 0; std::chrono::steady_clock::now() < deadline; ++i) {
      if (engine.chain(frame(i, counter_), not_live) != GST_FLOW_OK) return;
    }
  });
  ASSERT_TRUE(downstream_.wait_for(2));
  engine.begin_flush();  // what a pad's deactivation does first: the producer stops waiting
  producer.join();
  engine_.reset();
  downstream_.clear();
  EXPECT_EQ(counter_.freed.load(), counter_.made.load());
}

// A flush while frames stream: the tasks pause, what was queued and in flight is dropped, the
// stream starts anew (its first frame leaves without flow) and frames flow again.
TEST_F(FlowEngineTest, AFlushUnderLoadRestartsTheStream) {
  FlowEngine& engine = make_engine(model::Behaviour::every_pair);
  begin_stream(engine);
  std::atomic<bool> stop{false};
  std::atomic<int> next{0};
  std::thread producer([&] {
    while (!stop) engine.chain(frame(next++, counter_), not_live);  // FLUSHING during the flush
  });
  ASSERT_TRUE(downstream_.wait_for(2));
  engine.begin_flush();
  engine.pause_for_flush();
  int delivered_before = -1;
  EXPECT_TRUE(engine.end_flush([&] {
    delivered_before = downstream_.size();  // the tasks are paused: nothing is pushed meanwhile
    return true;
  }));
  ASSERT_TRUE(downstream_.wait_for(delivered_before + 2));
  stop = true;
  engine.begin_flush();  // unblocks a producer waiting for room
  producer.join();
  engine.stop();
  const std::vector<GstBuffer*> out = downstream_.buffers();
  EXPECT_EQ(neuflow_buffer_get_flow_meta(out[static_cast<std::size_t>(delivered_before)]), nullptr)
      << "the first frame after a flush has no previous frame";
  EXPECT_NE(neuflow_buffer_get_flow_meta(out[static_cast<std::size_t>(delivered_before) + 1]), nullptr);
  engine_.reset();
  downstream_.clear();
  EXPECT_EQ(counter_.freed.load(), counter_.made.load());
}

// Downstream refuses a buffer: the element posts an error, sends EOS downstream, and upstream's
// next chain() returns the failure; a serialized query does not wait forever.
TEST_F(FlowEngineTest, ADownstreamFailureReachesUpstream) {
  downstream_.fail_at = 1;
  FlowEngine& engine = make_engine(model::Behaviour::every_pair);
  begin_stream(engine);
  GstFlowReturn ret = GST_FLOW_OK;
  for (int i = 0; i < 50 && ret == GST_FLOW_OK; ++i) {
    ret = engine.chain(frame(i, counter_), not_live);
    if (ret == GST_FLOW_OK && i >= 2) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(ret, GST_FLOW_ERROR);
  EXPECT_TRUE(downstream_.wait_for_eos());
  EXPECT_FALSE(engine.drain());
  EXPECT_TRUE(error_posted());
  engine.stop();
  engine_.reset();
  downstream_.clear();
  EXPECT_EQ(counter_.freed.load(), counter_.made.load());
}

TEST_F(FlowEngineTest, AFrameBeforeItsCapsIsAnError) {
  FlowEngine& engine = make_engine(model::Behaviour::every_pair);
  ASSERT_TRUE(engine.start());
  ASSERT_EQ(engine.chain(frame(0, counter_), not_live), GST_FLOW_OK);  // queued; the worker fails it
  GstFlowReturn ret = GST_FLOW_OK;
  for (int i = 1; i < 100 && ret == GST_FLOW_OK; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
    ret = engine.chain(frame(i, counter_), not_live);
  }
  EXPECT_EQ(ret, GST_FLOW_NOT_NEGOTIATED);
  EXPECT_TRUE(error_posted());
  engine.stop();
  engine_.reset();
  EXPECT_EQ(counter_.freed.load(), counter_.made.load());
}

}  // namespace
}  // namespace neuflow::gst
