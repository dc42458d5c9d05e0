// The Vulkan backend as a user relies on it: the same flow and stages as the CPU at a size
// that is not a multiple of 16 with other iteration counts, streaming equal to pairs, and
// failures (a device that does not exist, device memory running out, a lost device) that are
// errors naming the device, after which a new session works; backend=auto falls back to the
// CPU with one warning. Runs on lavapipe in CI, under the validation layer.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <optional>

#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "support/camera_frames.hpp"
#include "support/fixtures.hpp"
#include "support/flow_difference.hpp"
#include "support/flow_error.hpp"
#include "support/vulkan.hpp"

namespace neuflow::model {
namespace {

ImageView view_of(const cv::Mat& m) {
  return ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), ChannelOrder::bgr};
}

struct Errors {
  double max = 0, mean = 0;
};

Errors compare(const float* a, const float* b, std::size_t n) {
  Errors e;
  for (std::size_t i = 0; i < n; ++i) {
    const double d = std::fabs(static_cast<double>(a[i]) - b[i]);
    e.max = std::max(e.max, d);
    e.mean += d;
  }
  e.mean /= static_cast<double>(std::max<std::size_t>(n, 1));
  return e;
}

Errors compare(const flow::FlowField& a, const flow::FlowField& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  return compare(a.uv.data(), b.uv.data(), std::min(a.uv.size(), b.uv.size()));
}

class VulkanSession : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
    NEUFLOW_REQUIRE_FIXTURE(frames, "frames");
    NEUFLOW_REQUIRE_VULKAN();
    if (!model_) model_ = FlowModel::load(checkpoint);
    frames_ = test::camera_frames(frames, 3, cv::Size(200, 120));  // → 208×128 padded
  }
  void TearDown() override { NEUFLOW_EXPECT_NO_VALIDATION_MESSAGES(); }

  // A Vulkan session made with `variable` set to `value` is refused with an error naming the
  // variable; the variable is unset again.
  static void expect_refused(const char* variable, const char* value) {
    ASSERT_EQ(setenv(variable, value, 1), 0);
    try {
      FlowSession bad(model_, {.backend = Backend::vulkan});
      ADD_FAILURE() << variable << "=" << value << " was accepted";
    } catch (const std::invalid_argument& error) {
      EXPECT_NE(std::string(error.what()).find(variable), std::string::npos) << error.what();
    }
    unsetenv(variable);
  }

  static std::shared_ptr<const FlowModel> model_;
  std::vector<cv::Mat> frames_;
};

std::shared_ptr<const FlowModel> VulkanSession::model_;

TEST_F(VulkanSession, EveryStageEqualsTheCpuAtAnOddSizeAndOtherIterations) {
  const Iterations iterations{2, 3};
  FlowSession cpu(model_, {.iterations = iterations, .threads = 2, .backend = Backend::cpu});
  FlowSession gpu(model_, {.iterations = iterations, .threads = 2, .backend = Backend::vulkan});
  EXPECT_EQ(cpu.backend_description(), "cpu");
  EXPECT_NE(gpu.backend_description().find("vulkan device"), std::string::npos) << gpu.backend_description();
  std::map<std::string, std::vector<float>> cpu_stages;
  cpu.set_observer([&](const StageTensor& t) {
    cpu_stages[t.name + "#" + std::to_string(t.frame)] =
        std::vector<float>(t.data, t.data + static_cast<std::size_t>(t.height) * t.width * t.channels);
  });
  int compared = 0;
  gpu.set_observer([&](const StageTensor& t) {
    const auto it = cpu_stages.find(t.name + "#" + std::to_string(t.frame));
    ASSERT_NE(it, cpu_stages.end()) << t.name;
    const std::size_t n = static_cast<std::size_t>(t.height) * t.width * t.channels;
    ASSERT_EQ(it->second.size(), n) << t.name;
    double magnitude = 0;
    for (float v : it->second) magnitude = std::max(magnitude, static_cast<double>(std::fabs(v)));
    const Errors e = compare(t.data, it->second.data(), n);
    if (t.name == "flow") {
      EXPECT_LT(e.max, 1e-2) << t.name;
      EXPECT_LT(e.mean, 1e-3) << t.name;
    } else {
      EXPECT_LT(e.max, 1e-3 * std::max(magnitude, 1.0)) << t.name << " frame " << t.frame << " (mean " << e.mean << ")";
    }
    ++compared;
  });
  const auto expected = cpu.compute(view_of(frames_[0]), view_of(frames_[1]));
  const auto got = gpu.compute(view_of(frames_[0]), view_of(frames_[1]));
  // 5 backbone + 2 attention + matching + 2 × (3 per s16 iteration) + 3 merges + 3 × 3 + flow
  EXPECT_EQ(compared, 5 + 2 + 1 + 2 * 3 + 3 + 3 * 3 + 1);
  const Errors e = compare(got, expected);
  EXPECT_EQ(got.width, 200);
  EXPECT_EQ(got.height, 120);
  EXPECT_LT(e.max, 1e-2);
  EXPECT_LT(e.mean, 1e-3);
}

// The stride-1 3×3 convolutions by the fused Winograd kernel (the default, which every other
// test here runs), by Winograd in three dispatches (NEUFLOW_VULKAN_CONV=winograd-split, what the
// tensor-core products take) and by the direct implicit GEMM (NEUFLOW_VULKAN_CONV=direct, the
// way back) give the CPU's flow. Both run through the scalar products (matmul.comp: with every
// convolution direct, all of them but the attention's; split, the 36 batched Winograd products
// too), here in each tile they take (NEUFLOW_VULKAN_GEMM_TILE; auto, the default every other test
// runs, takes them by the grid): every output's products are summed in the same order at every
// size, so the flows agree to the bit. A bad value of either variable is an error naming it.
TEST_F(VulkanSession, EveryWayOfConvolvingGivesTheCpusFlow) {
  FlowSession cpu(model_, {.threads = 2, .backend = Backend::cpu});
  const auto expected = cpu.compute(view_of(frames_[0]), view_of(frames_[1]));
  const auto flow_with = [&](const char* conv, const char* tile) {
    EXPECT_EQ(setenv("NEUFLOW_VULKAN_CONV", conv, 1), 0);
    EXPECT_EQ(setenv("NEUFLOW_VULKAN_GEMM_TILE", tile, 1), 0);
    FlowSession gpu(model_, {.backend = Backend::vulkan});
    auto flow = gpu.compute(view_of(frames_[0]), view_of(frames_[1]));
    unsetenv("NEUFLOW_VULKAN_CONV");
    unsetenv("NEUFLOW_VULKAN_GEMM_TILE");
    const Errors e = compare(flow, expected);
    EXPECT_LT(e.max, 1e-2) << conv << ", " << tile << " tiles";
    EXPECT_LT(e.mean, 1e-3) << conv << ", " << tile << " tiles";
    return flow;
  };
  EXPECT_EQ(test::differing_values(flow_with("direct", "32"), flow_with("direct", "128")), 0U)
      << "32×32 against 128×128 tiles";
  EXPECT_EQ(test::differing_values(flow_with("winograd-split", "64"), flow_with("winograd-split", "128")), 0U)
      << "64×64 against 128×128 tiles";
  expect_refused("NEUFLOW_VULKAN_CONV", "fast");
  expect_refused("NEUFLOW_VULKAN_GEMM_TILE", "96");
}

// An unobserved pass records some ops inside others' dispatches (a refinement step's update in
// the next step's correlation, at both scales with these iterations, and at 1/8, where the
// layers take Winograd at this size, that correlation beside the step's conv3; a scale's last
// update with the resample of its flow that follows it; both parts of a concatenation; the
// attention's BatchNorm in its LayerNorm; each 8-bit frame's conversion and its pyramid's three
// poolings in one): its flow is still the CPU's, also where a scale has no steps (the 1/16 flow
// then goes to 1/8 by itself, or the 1/16 step's update is followed by the upsampler's input).
TEST_F(VulkanSession, FusedDispatchesGiveTheCpusFlowAtBothScales) {
  cv::Mat a, b;
  cv::resize(frames_[0], a, cv::Size(160, 128), 0, 0, cv::INTER_AREA);
  cv::resize(frames_[1], b, cv::Size(160, 128), 0, 0, cv::INTER_AREA);
  const Iterations iterations{2, 3};
  FlowSession cpu(model_, {.iterations = iterations, .threads = 2, .backend = Backend::cpu});
  FlowSession gpu(model_, {.iterations = iterations, .backend = Backend::vulkan});
  const Errors e = compare(gpu.compute(view_of(a), view_of(b)), cpu.compute(view_of(a), view_of(b)));
  EXPECT_LT(e.max, 1e-2);
  EXPECT_LT(e.mean, 1e-3);
  // Every correlation in the update's form (each scale's first one starts the step input), but
  // the 1/8 ones after a step, beside its conv3; the 1/8 scale's last update beside its conv3.
  EXPECT_EQ(test::dispatches_of(gpu.device_work(), "local_correlation_update"), iterations.s16 + 1);
  EXPECT_EQ(test::dispatches_of(gpu.device_work(), "winograd_conv_step"), iterations.s8 - 1);
  EXPECT_EQ(test::dispatches_of(gpu.device_work(), "winograd_conv_step_end"), 1);
  EXPECT_EQ(test::dispatches_of(gpu.device_work(), "refine_update"), 1) << "the 1/16 layers are direct here";
  EXPECT_EQ(test::dispatches_of(gpu.device_work(), "frame_pyramid"), 2) << "one a frame";
  for (const Iterations other : {Iterations{1, 0}, Iterations{0, 2}}) {
    SCOPED_TRACE(std::to_string(other.s16) + "+" + std::to_string(other.s8));
    FlowSession cpu_other(model_, {.iterations = other, .threads = 2, .backend = Backend::cpu});
    FlowSession gpu_other(model_, {.iterations = other, .backend = Backend::vulkan});
    const Errors o = compare(gpu_other.compute(view_of(a), view_of(b)), cpu_other.compute(view_of(a), view_of(b)));
    EXPECT_LT(o.max, 1e-2);
    EXPECT_LT(o.mean, 1e-3);
  }
  // At 320×256 the 1/16 layers take Winograd too (conv3 from 128 channels there): that scale's
  // last step ends beside its conv3 as well, also writing the 1/8 flow, upsampled. (Two steps
  // at 1/16 would test its correlation beside conv3 too, but the CPU's memory plan refuses them
  // at this size.)
  cv::resize(frames_[0], a, cv::Size(320, 256), 0, 0, cv::INTER_AREA);
  cv::resize(frames_[1], b, cv::Size(320, 256), 0, 0, cv::INTER_AREA);
  FlowSession cpu_large(model_, {.iterations = {1, 1}, .threads = 2, .backend = Backend::cpu});
  FlowSession gpu_large(model_, {.iterations = {1, 1}, .backend = Backend::vulkan});
  const Errors l = compare(gpu_large.compute(view_of(a), view_of(b)), cpu_large.compute(view_of(a), view_of(b)));
  EXPECT_LT(l.max, 1e-2);
  EXPECT_LT(l.mean, 1e-3);
  EXPECT_EQ(test::dispatches_of(gpu_large.device_work(), "winograd_conv_step_end"), 2);
  EXPECT_EQ(test::dispatches_of(gpu_large.device_work(), "refine_update"), 0);
}

TEST_F(VulkanSession, StreamingGivesTheSameFlowAsPairs) {
  // Smaller than the other tests' frames (→ 112×64 padded): five passes on lavapipe, where the
  // size changes nothing this test checks but its time.
  std::vector<cv::Mat> f(3);
  for (int i = 0; i < 3; ++i) cv::resize(frames_[i], f[i], cv::Size(100, 60), 0, 0, cv::INTER_AREA);
  FlowSession pairs(model_, {.iterations = {1, 2}, .backend = Backend::vulkan});
  FlowSession stream(model_, {.iterations = {1, 2}, .backend = Backend::vulkan});
  EXPECT_FALSE(stream.push(view_of(f[0])).has_value());
  const auto s01 = stream.push(view_of(f[1]));
  // A pair computed in between must not disturb the stream.
  const auto p01 = stream.compute(view_of(f[0]), view_of(f[1]));
  const auto s12 = stream.push(view_of(f[2]));
  ASSERT_TRUE(s01 && s12);
  const auto p12 = pairs.compute(view_of(f[1]), view_of(f[2]));
  EXPECT_LT(compare(*s01, p01).max, 1e-5);
  EXPECT_LT(compare(*s12, p12).max, 1e-5);
  EXPECT_GT(compare(p01, p12).max, 1e-3) << "different pairs should give different flows";
}

// Pipelined streaming through the staging ring: two frames in flight give exactly push()'s
// flows (the same shaders on the same data), also with a pair computed in between, a frame
// converted on the CPU (a resize) and a change of frame size; the limit is an error, not a
// wait; a session destroyed with a frame in flight waits for it (the validation layer sees
// every buffer released after its last use).
TEST_F(VulkanSession, PipelinedStreamingGivesPushsFlows) {
  std::vector<cv::Mat> f(4);
  for (int i = 0; i < 4; ++i) cv::resize(frames_[i % 3], f[i], cv::Size(100, 60), 0, 0, cv::INTER_AREA);
  cv::flip(f[3], f[3], 1);  // a fourth frame unlike the others
  const SessionOptions options{.iterations = {1, 2}, .backend = Backend::vulkan};
  FlowSession reference(model_, options);
  std::vector<std::optional<flow::FlowField>> expected;
  expected.reserve(f.size());
  for (const auto& m : f) expected.push_back(reference.push(view_of(m)));

  FlowSession pipe(model_, options);
  EXPECT_EQ(pipe.max_in_flight(), 2);
  pipe.submit(view_of(f[0]));
  pipe.submit(view_of(f[1]));
  EXPECT_EQ(pipe.in_flight(), 2);
  EXPECT_THROW(pipe.submit(view_of(f[2])), std::logic_error);
  EXPECT_THROW(pipe.push(view_of(f[2])), std::logic_error);
  EXPECT_FALSE(pipe.take().has_value()) << "the first frame has no pair";
  pipe.submit(view_of(f[2]));
  const auto pair01 = pipe.compute(view_of(f[0]), view_of(f[1]));  // with a frame in flight
  std::vector<std::optional<flow::FlowField>> got{std::nullopt};
  got.push_back(pipe.take());
  pipe.submit(view_of(f[3]));
  got.push_back(pipe.take());
  EXPECT_TRUE(pipe.device_stage_times().empty()) << "finished early by compute(): its times are not kept";
  got.push_back(pipe.take());
  if (list_gpu_devices().at(0).timestamps) {
    EXPECT_FALSE(pipe.device_stage_times().empty()) << "the device's times of the frame just taken";
  }
  EXPECT_EQ(pipe.in_flight(), 0);
  EXPECT_THROW(pipe.take(), std::logic_error);
  for (std::size_t i = 1; i < f.size(); ++i) {
    ASSERT_TRUE(expected[i] && got[i]) << i;
    EXPECT_EQ(compare(*got[i], *expected[i]).max, 0) << "pair " << i - 1 << "-" << i;
  }
  EXPECT_LT(compare(pair01, *expected[1]).max, 1e-5);

  // A new frame size while a frame is in flight: that frame is finished on the old plan.
  cv::Mat s0, s1;
  cv::resize(f[0], s0, cv::Size(64, 48));
  cv::resize(f[1], s1, cv::Size(64, 48));
  pipe.submit(view_of(f[0]));
  pipe.submit(view_of(s0));
  EXPECT_TRUE(pipe.take().has_value()) << "the stream goes on from f[3]";
  EXPECT_FALSE(pipe.take().has_value()) << "a new size starts the stream anew";
  pipe.submit(view_of(s1));
  const auto small = pipe.take();
  ASSERT_TRUE(small);
  EXPECT_EQ(small->width, 64);
  FlowSession small_reference(model_, options);
  EXPECT_LT(compare(*small, small_reference.compute(view_of(s0), view_of(s1))).max, 1e-5);

  // Resized to the model size on the CPU, then up through the ring as floats.
  SessionOptions resized = options;
  resized.model_width = 96;
  resized.model_height = 64;
  FlowSession resized_push(model_, resized), resized_pipe(model_, resized);
  resized_push.push(view_of(f[0]));
  const auto r01 = resized_push.push(view_of(f[1]));
  resized_pipe.submit(view_of(f[0]));
  resized_pipe.submit(view_of(f[1]));
  resized_pipe.take();
  const auto p01 = resized_pipe.take();
  ASSERT_TRUE(r01 && p01);
  EXPECT_EQ(compare(*p01, *r01).max, 0);

  pipe.submit(view_of(s0));
  pipe.submit(view_of(s1));  // left in flight: the destructor waits for both
}

// A device lost while a frame is in flight: the submission that finds it lost fails naming
// the device; the frame in flight fails from its own take(), also after compute() finished it
// early (so each submit() still has one take()); a new session streams again.
TEST_F(VulkanSession, ADeviceLostWhileAFrameIsInFlightFailsItAndANewSessionStreams) {
  cv::Mat a, b;
  cv::resize(frames_[0], a, cv::Size(64, 48));
  cv::resize(frames_[1], b, cv::Size(64, 48));
  const SessionOptions options{.iterations = {1, 1}, .backend = Backend::vulkan, .device = 0};
  const auto expect_lost = [](const BackendError& e) {
    EXPECT_EQ(e.kind(), BackendError::Kind::device_lost) << e.what();
    EXPECT_NE(std::string(e.what()).find("vulkan device 0"), std::string::npos) << e.what();
  };
  ASSERT_EQ(setenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER", "6", 1), 0);
  {
    FlowSession session(model_, options);
    unsetenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER");
    bool lost = false;
    int taken = 0;
    for (int i = 0; i < 12 && !lost; ++i) {
      if (session.in_flight() == session.max_in_flight()) {
        session.take();  // finished before the loss
        ++taken;
      }
      try {
        session.submit(view_of(i % 2 ? b : a));
      } catch (const BackendError& e) {
        expect_lost(e);
        lost = true;
      }
    }
    ASSERT_TRUE(lost) << "the device was not lost in 12 frames";
    EXPECT_GT(taken, 0) << "frames streamed before the loss";
    ASSERT_EQ(session.in_flight(), 1) << "the frame before the failed submission is in flight";
    try {
      session.compute(view_of(a), view_of(b));  // finishes the frame in flight first
      ADD_FAILURE() << "computed on a lost device";
    } catch (const BackendError& e) {
      expect_lost(e);
    }
    EXPECT_EQ(session.in_flight(), 1) << "its failure waits for its take()";
    try {
      session.take();
      ADD_FAILURE() << "a frame in flight when the device was lost gave a flow";
    } catch (const BackendError& e) {
      expect_lost(e);
    }
    EXPECT_EQ(session.in_flight(), 0);
  }
  FlowSession again(model_, options);
  again.submit(view_of(a));
  again.submit(view_of(b));
  EXPECT_FALSE(again.take().has_value());
  const auto flow = again.take();
  ASSERT_TRUE(flow);
  EXPECT_EQ(flow->width, 64);
}

// In padding mode the device converts the frame from its 8-bit pixels (frame_u8.comp): at an
// odd offset in its padding, in either channel order, with a row stride longer than the row;
// a resize is converted on the CPU. Each gives the CPU backend's flow.
TEST_F(VulkanSession, FramesConvertedOnTheDeviceGiveTheCpusFlow) {
  cv::Mat bgr0, bgr1;
  cv::resize(frames_[0], bgr0, cv::Size(100, 60), 0, 0, cv::INTER_AREA);  // → 112×64, padded 6 left, 2 top
  cv::resize(frames_[1], bgr1, cv::Size(100, 60), 0, 0, cv::INTER_AREA);
  const SessionOptions gpu_options{.iterations = {1, 1}, .backend = Backend::vulkan, .device = 0};
  const SessionOptions cpu_options{.iterations = {1, 1}, .threads = 2, .backend = Backend::cpu};
  FlowSession gpu(model_, gpu_options), cpu(model_, cpu_options);
  const auto expected = cpu.compute(view_of(bgr0), view_of(bgr1));
  const auto from_bgr = gpu.compute(view_of(bgr0), view_of(bgr1));
  Errors e = compare(from_bgr, expected);
  EXPECT_LT(e.max, 1e-2);
  EXPECT_LT(e.mean, 1e-3);

  cv::Mat rgb0, rgb1;
  cv::cvtColor(bgr0, rgb0, cv::COLOR_BGR2RGB);
  cv::cvtColor(bgr1, rgb1, cv::COLOR_BGR2RGB);
  ImageView v0 = view_of(rgb0), v1 = view_of(rgb1);
  v0.order = v1.order = ChannelOrder::rgb;
  EXPECT_EQ(compare(gpu.compute(v0, v1), from_bgr).max, 0) << "the same pixels in the other channel order";

  cv::Mat wide0(60, 130, CV_8UC3, cv::Scalar(0, 0, 255)), wide1 = wide0.clone();
  bgr0.copyTo(wide0(cv::Rect(17, 0, 100, 60)));
  bgr1.copyTo(wide1(cv::Rect(17, 0, 100, 60)));
  EXPECT_EQ(
      compare(gpu.compute(view_of(wide0(cv::Rect(17, 0, 100, 60))), view_of(wide1(cv::Rect(17, 0, 100, 60)))), from_bgr)
          .max,
      0)
      << "rows read at their stride";

  SessionOptions resized_gpu = gpu_options, resized_cpu = cpu_options;
  resized_gpu.model_width = resized_cpu.model_width = 96;
  resized_gpu.model_height = resized_cpu.model_height = 64;
  FlowSession gpu_resize(model_, resized_gpu), cpu_resize(model_, resized_cpu);
  e = compare(gpu_resize.compute(view_of(bgr0), view_of(bgr1)), cpu_resize.compute(view_of(bgr0), view_of(bgr1)));
  EXPECT_LT(e.max, 1e-2);
  EXPECT_LT(e.mean, 1e-3);
}

TEST_F(VulkanSession, ADeviceThatDoesNotExistIsAnErrorNamingIt) {
  try {
    FlowSession session(model_, {.backend = Backend::vulkan, .device = 63});
    FAIL() << "no error";
  } catch (const BackendError& e) {
    EXPECT_EQ(e.kind(), BackendError::Kind::unavailable);
    EXPECT_NE(std::string(e.what()).find("no Vulkan device 63"), std::string::npos) << e.what();
  }
  // backend=auto with that device runs on the CPU.
  FlowSession fallback(model_, {.iterations = {1, 1}, .backend = Backend::automatic, .device = 63});
  EXPECT_EQ(fallback.backend_description(), "cpu");
  EXPECT_EQ(fallback.compute(view_of(frames_[0]), view_of(frames_[1])).width, 200);
}

// Each gtest case runs as its own process under ctest, so the budget applies to this one only.
TEST_F(VulkanSession, RunningOutOfDeviceMemoryIsAnErrorAndAutoFallsBackToTheCpu) {
  // The weights (35 MiB) and a 64×48 plan fit (36 MiB passes too), a 208×128 plan (38 MiB in all
  // would still fail, 39 not) does not.
  ASSERT_EQ(setenv("NEUFLOW_VULKAN_MEMORY_BUDGET_MB", "37", 1), 0);
  {
    FlowSession session(model_, {.iterations = {1, 1}, .backend = Backend::vulkan, .device = 0});
    try {
      session.compute(view_of(frames_[0]), view_of(frames_[1]));
      FAIL() << "no error";
    } catch (const BackendError& e) {
      EXPECT_EQ(e.kind(), BackendError::Kind::out_of_memory);
      EXPECT_NE(std::string(e.what()).find("vulkan device 0"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("out of device memory"), std::string::npos) << e.what();
    }
    // The failed plan released what it had: a session at a size that fits works on the same device.
    cv::Mat a, b;
    cv::resize(frames_[0], a, cv::Size(64, 48));
    cv::resize(frames_[1], b, cv::Size(64, 48));
    FlowSession small(model_, {.iterations = {1, 1}, .backend = Backend::vulkan, .device = 0});
    EXPECT_EQ(small.compute(view_of(a), view_of(b)).width, 64);
  }
  FlowSession fallback(model_, {.iterations = {1, 1}, .backend = Backend::automatic, .device = 0});
  const auto f = fallback.compute(view_of(frames_[0]), view_of(frames_[1]));
  EXPECT_EQ(f.width, 200);
  EXPECT_EQ(fallback.backend_description(), "cpu");
  EXPECT_NE(fallback.fallback_warning().find("out of device memory"), std::string::npos) << fallback.fallback_warning();
  unsetenv("NEUFLOW_VULKAN_MEMORY_BUDGET_MB");
}

// A lost device (NEUFLOW_VULKAN_LOSE_DEVICE_AFTER stands in for a GPU hang or reset) is an error
// naming the device; that session stays failed and says to start a new one; a new session opens
// the device again and gives the same flow as before the loss.
TEST_F(VulkanSession, ALostDeviceIsAnErrorNamingItAndANewSessionRunsAgain) {
  cv::Mat a, b;
  cv::resize(frames_[0], a, cv::Size(64, 48));
  cv::resize(frames_[1], b, cv::Size(64, 48));
  const SessionOptions options{.iterations = {1, 1}, .backend = Backend::vulkan, .device = 0};
  flow::FlowField before;
  {
    FlowSession session(model_, options);
    before = session.compute(view_of(a), view_of(b));
  }
  ASSERT_EQ(setenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER", "3", 1), 0);
  {
    std::optional<FlowSession> session;
    try {
      session.emplace(model_, options);  // the device is opened again, with the variable set
      for (int i = 0; i < 8; ++i) session->compute(view_of(a), view_of(b));
      ADD_FAILURE() << "the device was not lost in 8 pairs";
    } catch (const BackendError& e) {
      EXPECT_EQ(e.kind(), BackendError::Kind::device_lost) << e.what();
      EXPECT_NE(std::string(e.what()).find("vulkan device 0"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("lost"), std::string::npos) << e.what();
    }
    unsetenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER");
    if (session) {
      try {
        session->compute(view_of(a), view_of(b));
        ADD_FAILURE() << "a session on a lost device computed again";
      } catch (const BackendError& e) {
        EXPECT_EQ(e.kind(), BackendError::Kind::device_lost) << e.what();
        EXPECT_NE(std::string(e.what()).find("start a new session"), std::string::npos) << e.what();
      }
    }
  }
  unsetenv("NEUFLOW_VULKAN_LOSE_DEVICE_AFTER");
  FlowSession again(model_, options);
  const auto after = again.compute(view_of(a), view_of(b));
  const auto e = compare(before, after);
  EXPECT_EQ(e.max, 0.0) << "the same pair on a newly opened device";
}

// fp16 storage against fp32 on the same device, at two sizes. The bound (documented in
// docs/benchmarks.md) is on the end-point error: mean under 0.5 % of the mean flow magnitude,
// and no pixel off by more than 1 % of the largest vector (measured on lavapipe: 0.13-0.14 % and
// 0.23-0.26 %). The random-weight fixture model gives
// large flows (over 100 px), so the bound is relative.
TEST_F(VulkanSession, Fp16StaysWithinItsBoundOfFp32) {
  bool fp16 = false;
  for (const auto& d : list_gpu_devices()) fp16 = fp16 || (d.index == 0 && d.fp16);
  if (!fp16) GTEST_SKIP() << "Vulkan device 0 has no fp16";
  FlowSession fp32_session(model_, {.iterations = {1, 4}, .backend = Backend::vulkan, .device = 0});
  FlowSession fp16_session(
      model_, {.iterations = {1, 4}, .backend = Backend::vulkan, .device = 0, .precision = Precision::fp16});
  EXPECT_NE(fp16_session.backend_description().find("fp16"), std::string::npos) << fp16_session.backend_description();
  EXPECT_TRUE(fp16_session.fallback_warning().empty()) << fp16_session.fallback_warning();
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{128, 96}, {200, 120}}) {
    cv::Mat a, b;
    cv::resize(frames_[0], a, cv::Size(w, h));
    cv::resize(frames_[1], b, cv::Size(w, h));
    const test::Fp16Error e = test::fp16_error(fp32_session.compute(view_of(a), view_of(b)),
                                               fp16_session.compute(view_of(a), view_of(b)), w, h);
    RecordProperty("fp16_mean_epe_" + std::to_string(w) + "x" + std::to_string(h), std::to_string(e.epe));
    EXPECT_LT(e.epe, 0.005 * e.magnitude) << w << "x" << h;
    EXPECT_LT(e.worst, 0.01 * e.largest) << w << "x" << h;
  }
}

// What neuflow-bench-core's vulkan_stream_stages prints: the GPU's own time of each stage of
// a streamed frame, named as the observer's stages (a refinement iteration as one), in the
// order they ran, adding up to no more than the host's time for the whole push.
TEST_F(VulkanSession, DeviceTimestampsTimeEveryStageOfAFrame) {
  if (!list_gpu_devices().at(0).timestamps) GTEST_SKIP() << "Vulkan device 0 has no timestamps on its compute queue";
  const Iterations iterations{1, 2};
  FlowSession gpu(model_, {.iterations = iterations, .backend = Backend::vulkan, .device = 0});
  cv::Mat f0, f1;  // small: the stages' names and order are the same at any size
  cv::resize(frames_[0], f0, cv::Size(96, 64), 0, 0, cv::INTER_AREA);
  cv::resize(frames_[1], f1, cv::Size(96, 64), 0, 0, cv::INTER_AREA);
  // The flow pass's stages as the observer sees them, less the backbone's (which that pass
  // reads, not computes) and with an iteration's corr_/hidden/delta tensors as one stage.
  std::vector<std::string> flow_stages;
  gpu.set_observer([&](const StageTensor& t) {
    std::string name = t.name;
    if (name.rfind("backbone_", 0) == 0 || name == "conv_s8") return;
    if (name.rfind("corr_", 0) == 0) name = "refine_" + name.substr(5);
    if (name == "context_merge_s8") name = "merge_s8";  // merged beside the features, one stage
    if (name.size() > 7 && (name.ends_with("_hidden") || name.ends_with("_delta"))) return;
    if (flow_stages.empty() || flow_stages.back() != name) flow_stages.push_back(name);
  });
  gpu.push(view_of(f0));
  EXPECT_TRUE(gpu.device_stage_times().empty()) << "an observed pass is not timed";
  gpu.push(view_of(f1));
  gpu.set_observer(nullptr);

  gpu.push(view_of(f0));
  const auto t0 = std::chrono::steady_clock::now();
  ASSERT_TRUE(gpu.push(view_of(f1)).has_value());
  const double host_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  const auto& times = gpu.device_stage_times();
  std::vector<std::string> timed;
  double device_ms = 0;
  for (const auto& t : times) {
    timed.push_back(t.name);
    EXPECT_GE(t.milliseconds, 0) << t.name;
    device_ms += t.milliseconds;
  }
  // A streamed frame encodes one frame (the upsampler's features first, as the graph orders
  // them), then runs the flow pass.
  std::vector<std::string> expected{"conv_s8", "backbone_s8", "backbone_s16"};
  expected.insert(expected.end(), flow_stages.begin(), flow_stages.end());
  EXPECT_EQ(timed, expected);
  // attention, matching, one 1/16 iteration, the merges (the features' and the context's, side
  // by side), two 1/8 iterations, the upsampled flow
  EXPECT_EQ(flow_stages.size(), 1u + 1 + 1 + 1 + 2 + 1);
  EXPECT_GT(device_ms, 0);
  EXPECT_LE(device_ms, host_ms * 1.01 + 0.1);

  FlowSession cpu(model_, {.iterations = iterations, .backend = Backend::cpu});
  cpu.push(view_of(f0));
  cpu.push(view_of(f1));
  EXPECT_TRUE(cpu.device_stage_times().empty());
}

// On a real GPU (CI has only lavapipe, a CPU device, so this skips there and never fails for
// it): backend=auto takes the first discrete or integrated GPU, and at the benchmarks' size
// its flows are the CPU's in fp32 and within fp16's bound of fp32 where the GPU has fp16.
TEST_F(VulkanSession, OnARealGpuAutoTakesItAndGivesTheCpusFlow) {
  if (test::only_software_vulkan()) {
    GTEST_SKIP() << "only software Vulkan devices here (lavapipe): this test needs a discrete or integrated GPU";
  }
  const auto devices = list_gpu_devices();
  const auto gpu = std::find_if(devices.begin(), devices.end(), [](const GpuDevice& d) { return d.is_gpu(); });
  ASSERT_NE(gpu, devices.end());
  const Iterations iterations{1, 4};
  FlowSession cpu(model_, {.iterations = iterations, .threads = 2, .backend = Backend::cpu});
  FlowSession automatic(model_, {.iterations = iterations, .backend = Backend::automatic});
  EXPECT_EQ(automatic.backend_description().rfind("vulkan device " + std::to_string(gpu->index) + " ", 0), 0u)
      << automatic.backend_description();
  EXPECT_TRUE(automatic.fallback_warning().empty()) << automatic.fallback_warning();
  cv::Mat a, b;
  cv::resize(frames_[0], a, cv::Size(768, 432));
  cv::resize(frames_[1], b, cv::Size(768, 432));
  const auto exact = automatic.compute(view_of(a), view_of(b));
  const Errors e = compare(exact, cpu.compute(view_of(a), view_of(b)));
  EXPECT_LT(e.max, 1e-2);
  EXPECT_LT(e.mean, 1e-3);
  if (!gpu->fp16) return;
  FlowSession half(model_, {.iterations = iterations, .backend = Backend::automatic, .precision = Precision::fp16});
  EXPECT_NE(half.backend_description().find(", fp16"), std::string::npos) << half.backend_description();
  const test::Fp16Error f = test::fp16_error(exact, half.compute(view_of(a), view_of(b)), 768, 432);
  EXPECT_LT(f.epe, 0.005 * f.magnitude);
  EXPECT_LT(f.worst, 0.01 * f.largest);
}

TEST(VulkanDevices, EachDeviceHasANameTypeAndMemory) {
  NEUFLOW_REQUIRE_VULKAN();
  const auto devices = list_gpu_devices();
  ASSERT_FALSE(devices.empty());
  for (std::size_t i = 0; i < devices.size(); ++i) {
    EXPECT_EQ(devices[i].index, static_cast<int>(i));
    EXPECT_FALSE(devices[i].name.empty());
    EXPECT_FALSE(devices[i].type.empty());
    EXPECT_GT(devices[i].max_buffer_bytes, 0u);
  }
}

}  // namespace
}  // namespace neuflow::model
