// FlowSession behaviour a user relies on: streaming equals pairs, any frame size, resize mode,
// channel order, clear errors, and one model shared by sessions on several threads.
#include <gtest/gtest.h>

#include <cstdlib>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <cstdio>
#include <thread>
#include <utility>

#include "frame_geometry.hpp"
#include "memory_limit.hpp"
#include "network.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/flow_model.hpp"
#include "neuflow/model/flow_session.hpp"
#include "support/camera_frames.hpp"
#include "support/fixtures.hpp"

namespace neuflow::model {
namespace {

ImageView view_of(const cv::Mat& m, ChannelOrder order = ChannelOrder::bgr) {
  return ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), order};
}

double max_abs_diff(const flow::FlowField& a, const flow::FlowField& b) {
  EXPECT_EQ(a.width, b.width);
  EXPECT_EQ(a.height, b.height);
  double m = 0;
  for (std::size_t i = 0; i < std::min(a.uv.size(), b.uv.size()); ++i) {
    m = std::max(m, static_cast<double>(std::fabs(a.uv[i] - b.uv[i])));
  }
  return m;
}

bool all_finite(const flow::FlowField& f) {
  return std::all_of(f.uv.begin(), f.uv.end(), [](float v) { return std::isfinite(v); });
}

class SessionTest : public ::testing::Test {
 protected:
  void SetUp() override {
    NEUFLOW_REQUIRE_FIXTURE(dir, "neuflow-v2-seed0/checkpoint.pth");
    NEUFLOW_REQUIRE_FIXTURE(frames, "frames");
    if (!model_) model_ = FlowModel::load(dir);
    frames_ = test::camera_frames(frames, 3, cv::Size(256, 144));
  }

  static std::shared_ptr<const FlowModel> model_;
  std::vector<cv::Mat> frames_;  // 256×144 (144 is not a multiple of 16: padding is exercised)
};

std::shared_ptr<const FlowModel> SessionTest::model_;

TEST_F(SessionTest, StreamingGivesTheSameFlowAsPairs) {
  FlowSession pairs(model_, {.threads = 2});
  FlowSession stream(model_, {.threads = 2});
  EXPECT_FALSE(stream.push(view_of(frames_[0])).has_value()) << "the first frame has no flow";
  const auto s01 = stream.push(view_of(frames_[1]));
  const auto s12 = stream.push(view_of(frames_[2]));
  ASSERT_TRUE(s01 && s12);
  const auto p01 = pairs.compute(view_of(frames_[0]), view_of(frames_[1]));
  const auto p12 = pairs.compute(view_of(frames_[1]), view_of(frames_[2]));
  EXPECT_EQ(s01->width, 256);
  EXPECT_EQ(s01->height, 144);
  EXPECT_LT(max_abs_diff(*s01, p01), 1e-5);
  EXPECT_LT(max_abs_diff(*s12, p12), 1e-5);
  EXPECT_GT(max_abs_diff(p01, p12), 1e-3) << "different pairs should give different flows";
}

// submit()/take() on the CPU: one frame in flight (submit computes it), the same flows as push().
TEST_F(SessionTest, SubmitAndTakeGiveThePushedFlowsOneFrameAtATimeOnTheCpu) {
  FlowSession pushed(model_, {.threads = 2});
  FlowSession submitted(model_, {.threads = 2});
  EXPECT_EQ(submitted.max_in_flight(), 1);
  for (int i = 0; i < 3; ++i) {
    const auto expected = pushed.push(view_of(frames_[i]));
    submitted.submit(view_of(frames_[i]));
    EXPECT_EQ(submitted.in_flight(), 1);
    EXPECT_THROW(submitted.submit(view_of(frames_[i])), std::logic_error) << "one in flight at most";
    const auto got = submitted.take();
    ASSERT_EQ(got.has_value(), expected.has_value()) << i;
    if (got) {
      EXPECT_EQ(max_abs_diff(*got, *expected), 0) << i;
    }
  }
  EXPECT_THROW(submitted.take(), std::logic_error) << "nothing in flight";
}

TEST_F(SessionTest, ResetAndSizeChangeStartANewStream) {
  FlowSession stream(model_, {.threads = 2});
  stream.push(view_of(frames_[0]));
  stream.reset();
  EXPECT_FALSE(stream.push(view_of(frames_[1])).has_value());
  ASSERT_TRUE(stream.push(view_of(frames_[2])).has_value());

  cv::Mat other;
  cv::resize(frames_[0], other, cv::Size(100, 60));
  EXPECT_FALSE(stream.push(view_of(other)).has_value()) << "a new size cannot pair with the old frames";
  cv::Mat other2;
  cv::resize(frames_[1], other2, cv::Size(100, 60));
  const auto f = stream.push(view_of(other2));
  ASSERT_TRUE(f.has_value());
  EXPECT_EQ(f->width, 100);
  EXPECT_EQ(f->height, 60);
  EXPECT_TRUE(all_finite(*f));
}

TEST_F(SessionTest, OddSizesArePaddedAndCroppedBack) {
  FlowSession session(model_, {.iterations = {1, 2}, .threads = 2});
  for (const auto& [w, h] : std::vector<std::pair<int, int>>{{32, 32}, {33, 47}, {211, 97}}) {
    cv::Mat a, b;
    cv::resize(frames_[0], a, cv::Size(w, h));
    cv::resize(frames_[1], b, cv::Size(w, h));
    const auto f = session.compute(view_of(a), view_of(b));
    EXPECT_EQ(f.width, w);
    EXPECT_EQ(f.height, h);
    EXPECT_TRUE(all_finite(f)) << w << "x" << h;
  }
}

TEST_F(SessionTest, ChannelOrderIsHonoured) {
  FlowSession session(model_, {.iterations = {1, 2}, .threads = 2});
  cv::Mat rgb0, rgb1;
  cv::cvtColor(frames_[0], rgb0, cv::COLOR_BGR2RGB);
  cv::cvtColor(frames_[1], rgb1, cv::COLOR_BGR2RGB);
  const auto from_bgr = session.compute(view_of(frames_[0]), view_of(frames_[1]));
  const auto from_rgb = session.compute(view_of(rgb0, ChannelOrder::rgb), view_of(rgb1, ChannelOrder::rgb));
  EXPECT_LT(max_abs_diff(from_bgr, from_rgb), 1e-6);
  const auto swapped = session.compute(view_of(frames_[0], ChannelOrder::rgb), view_of(frames_[1], ChannelOrder::rgb));
  EXPECT_GT(max_abs_diff(from_bgr, swapped), 1e-3) << "feeding BGR as RGB must change the result";
}

TEST_F(SessionTest, RowStrideIsHonoured) {
  FlowSession session(model_, {.iterations = {1, 2}, .threads = 2});
  cv::Mat wide0(frames_[0].rows, frames_[0].cols + 13, CV_8UC3, cv::Scalar(255, 0, 255));
  cv::Mat wide1 = wide0.clone();
  frames_[0].copyTo(wide0(cv::Rect(0, 0, frames_[0].cols, frames_[0].rows)));
  frames_[1].copyTo(wide1(cv::Rect(0, 0, frames_[1].cols, frames_[1].rows)));
  const cv::Rect roi(0, 0, frames_[0].cols, frames_[0].rows);
  const auto strided = session.compute(view_of(wide0(roi)), view_of(wide1(roi)));
  const auto packed = session.compute(view_of(frames_[0]), view_of(frames_[1]));
  EXPECT_LT(max_abs_diff(strided, packed), 1e-6);
}

TEST_F(SessionTest, ResizeModeAtTheInputSizeEqualsPaddingMode) {
  cv::Mat a, b;
  cv::resize(frames_[0], a, cv::Size(256, 160));
  cv::resize(frames_[1], b, cv::Size(256, 160));
  FlowSession padded(model_, {.iterations = {1, 2}, .threads = 2});
  FlowSession resized(model_, {.iterations = {1, 2}, .model_width = 256, .model_height = 160, .threads = 2});
  EXPECT_LT(max_abs_diff(padded.compute(view_of(a), view_of(b)), resized.compute(view_of(a), view_of(b))), 1e-5);
  FlowSession smaller(model_, {.iterations = {1, 2}, .model_width = 128, .model_height = 96, .threads = 2});
  const auto f = smaller.compute(view_of(a), view_of(b));
  EXPECT_EQ(f.width, 256);
  EXPECT_EQ(f.height, 160);
  EXPECT_TRUE(all_finite(f));
}

// A model size whose plan would need more than max-memory is refused before the plan is made,
// with the size, the need and the limit; smaller frames still run.
TEST_F(SessionTest, APlanLargerThanMaxMemoryIsRefusedNamingTheNeed) {
  FlowSession session(model_, {.threads = 2, .max_memory_mb = 8});
  const auto problem = session.memory_problem(1280, 720);
  ASSERT_TRUE(problem.has_value());
  EXPECT_NE(problem->find("a 1280x720 model size needs about "), std::string::npos) << *problem;
  EXPECT_NE(problem->find("more than the 8 MiB max-memory allows"), std::string::npos) << *problem;
  cv::Mat big;
  cv::resize(frames_[0], big, cv::Size(1280, 720));
  try {
    session.push(view_of(big));
    FAIL() << "a plan over max-memory was made";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(std::string(e.what()), *problem);
  }
  cv::Mat small;
  cv::resize(frames_[0], small, cv::Size(64, 48));
  EXPECT_FALSE(session.memory_problem(64, 48).has_value());
  EXPECT_NO_THROW(session.push(view_of(small)));
  EXPECT_THROW(FlowSession(model_, {.max_memory_mb = -1}), std::invalid_argument);
}

// The estimate a limit is checked against covers what the CPU plan then allocates.
TEST_F(SessionTest, TheMemoryEstimateCoversTheCpuPlansAllocation) {
  for (const auto& [w, h] : {std::pair{320, 256}, std::pair{768, 432}}) {
    const NetworkPlan plan(model_->weights(), h, w, CpuConvolution::automatic);
    const std::size_t estimate = estimate_plan_bytes(model_->weights(), h, w);
    const std::size_t allocation = plan.memory().allocation;
    EXPECT_GE(estimate, allocation) << w << "x" << h;
    EXPECT_LE(estimate, 4 * allocation) << w << "x" << h << ": an estimate that refuses sizes that fit";
    std::printf("%dx%d: estimate %.1f MB, the CPU plan's allocation %.1f MB\n", w, h,
                static_cast<double>(estimate) / 1e6, static_cast<double>(allocation) / 1e6);
  }
}

TEST_F(SessionTest, UnusableInputsAreRejectedWithAReason) {
  FlowSession session(model_, {.threads = 2});
  cv::Mat tiny(20, 40, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(session.compute(view_of(tiny), view_of(tiny)), std::invalid_argument);
  cv::Mat other;
  cv::resize(frames_[1], other, cv::Size(128, 72));
  EXPECT_THROW(session.compute(view_of(frames_[0]), view_of(other)), std::invalid_argument);
  EXPECT_THROW(
      FlowSession(model_, {.model_width = 100, .model_height = 64}).compute(view_of(frames_[0]), view_of(frames_[1])),
      std::invalid_argument);
  EXPECT_THROW(FlowSession(model_, {.iterations = {-1, 8}}), std::invalid_argument);
  ImageView bad = view_of(frames_[0]);
  bad.stride = 10;
  EXPECT_THROW(session.compute(bad, bad), std::invalid_argument);
}

// The CPU's ways of computing the 3×3 convolutions (direct; Winograd with each layer's tile
// form, or F(4×4) or F(6×6) everywhere) give the same flow to rounding, the environment's
// NEUFLOW_CONV choosing for sessions that leave it automatic, and a value that is none of the
// names failing the session at creation with the variable's name.
TEST_F(SessionTest, DirectAndWinogradConvolutionsGiveTheSameFlow) {
  const auto flow_with = [&](CpuConvolution c) {
    FlowSession session(model_, {.threads = 2, .backend = Backend::cpu, .cpu_convolution = c});
    return session.compute(view_of(frames_[0]), view_of(frames_[1]));
  };
  const auto direct = flow_with(CpuConvolution::direct);
  for (const CpuConvolution c : {CpuConvolution::winograd, CpuConvolution::winograd4, CpuConvolution::winograd6}) {
    SCOPED_TRACE(std::string(cpu_convolution_name(c)));
    const auto winograd = flow_with(c);
    ASSERT_EQ(direct.uv.size(), winograd.uv.size());
    double sum = 0, worst = 0;
    for (std::size_t i = 0; i < direct.uv.size(); ++i) {
      const double d = std::fabs(direct.uv[i] - winograd.uv[i]);
      sum += d;
      worst = std::max(worst, d);
    }
    EXPECT_LE(worst, 1e-2) << "px";
    EXPECT_LE(sum / static_cast<double>(direct.uv.size()), 1e-3) << "px";
  }

  struct Unset {
    ~Unset() { ::unsetenv("NEUFLOW_CONV"); }
  } unset;
  ::setenv("NEUFLOW_CONV", "direct", 1);
  const auto from_environment = flow_with(CpuConvolution::automatic);
  EXPECT_EQ(from_environment.uv, direct.uv);
  ::setenv("NEUFLOW_CONV", "wingrad", 1);
  try {
    FlowSession bad(model_, {.threads = 2});
    ADD_FAILURE() << "a session was created with NEUFLOW_CONV=wingrad";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("NEUFLOW_CONV"), std::string::npos) << e.what();
  }
}

TEST_F(SessionTest, SessionsOnSeveralThreadsShareOneModel) {
  FlowSession reference(model_, {.iterations = {1, 2}, .threads = 1});
  const auto expected01 = reference.compute(view_of(frames_[0]), view_of(frames_[1]));
  const auto expected12 = reference.compute(view_of(frames_[1]), view_of(frames_[2]));
  std::vector<double> errors(4, 1.0);
  std::vector<std::thread> threads;
  threads.reserve(4);
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      FlowSession session(model_, {.iterations = {1, 2}, .threads = 1});
      double worst = 0;
      for (int i = 0; i < 2; ++i) {
        const int a = (t + i) % 2;
        const auto f = session.compute(view_of(frames_[a]), view_of(frames_[a + 1]));
        const auto& expected = a == 0 ? expected01 : expected12;
        for (std::size_t k = 0; k < f.uv.size(); ++k)
          worst = std::max(worst, static_cast<double>(std::fabs(f.uv[k] - expected.uv[k])));
      }
      errors[t] = worst;
    });
  }
  for (auto& th : threads) th.join();
  for (int t = 0; t < 4; ++t) EXPECT_LT(errors[t], 1e-5) << "thread " << t;
}

TEST(FlowModelSharing, OneInstancePerCheckpointWhileInUse) {
  NEUFLOW_REQUIRE_FIXTURE(path, "neuflow-v2-seed0/checkpoint.pth");
  auto a = FlowModel::load_shared(path);
  auto b = FlowModel::load_shared(path.parent_path() / "." / path.filename());  // another spelling
  EXPECT_EQ(a.get(), b.get());
  a.reset();
  b.reset();
  auto c = FlowModel::load_shared(path);  // released by all users: loaded anew
  EXPECT_NE(c.get(), nullptr);
  EXPECT_THROW(FlowModel::load_shared(path.parent_path() / "missing.pth"), CheckpointError);
}

TEST(FrameGeometry, ResizedFlowIsRescaledToInputPixels) {
  SessionOptions options;
  options.model_width = 160;
  options.model_height = 128;
  const FrameGeometry g = plan_geometry(320, 256, options);
  Tensor model_flow(128, 160, 2);
  for (std::size_t p = 0; p < model_flow.pixels(); ++p) {
    model_flow.data[2 * p] = 1.f;
    model_flow.data[2 * p + 1] = 2.f;
  }
  const auto f = restore_flow(model_flow, g);
  ASSERT_EQ(f.width, 320);
  ASSERT_EQ(f.height, 256);
  for (std::size_t p = 0; p < f.pixel_count(); ++p) {
    ASSERT_FLOAT_EQ(f.uv[2 * p], 2.f);
    ASSERT_FLOAT_EQ(f.uv[2 * p + 1], 4.f);
  }
}

TEST(FrameGeometry, PaddingIsCentredAndToMultiplesOf16) {
  const FrameGeometry g = plan_geometry(1242, 375, SessionOptions{});
  EXPECT_EQ(g.model_width, 1248);
  EXPECT_EQ(g.model_height, 384);
  EXPECT_EQ(g.pad_left, 3);
  EXPECT_EQ(g.pad_top, 4);
  EXPECT_FALSE(g.resize);
  EXPECT_THROW(plan_geometry(31, 100, SessionOptions{}), std::invalid_argument);
}

}  // namespace
}  // namespace neuflow::model
