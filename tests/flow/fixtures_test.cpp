// The ground-truth samples of the standard benchmarks in fixtures/flow-gt read with their
// documented sizes and survive conversion between the formats.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <ostream>

#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

#include "neuflow/flow/flow_io.hpp"
#include "neuflow/flow/metrics.hpp"
#include "support/fixtures.hpp"
#include "test_util.hpp"

namespace neuflow::flow {
namespace {

struct GroundTruth {
  const char* path;
  int width;
  int height;
  double min_valid_share;  // lower bound on the share of valid pixels
  double max_valid_share;
};

// The KITTI sample is sparse (LiDAR-based, ~16% valid); Sintel and FlyingChairs are dense;
// Middlebury marks a few unknown pixels.
const GroundTruth kGroundTruth[] = {
    {"flow-gt/middlebury/RubberWhale/flow10.flo", 584, 388, 0.80, 1.0},
    {"flow-gt/middlebury/Urban2/flow10.flo", 640, 480, 0.80, 1.0},
    {"flow-gt/sintel/alley_1_clean_0002/flow.flo", 1024, 436, 1.0, 1.0},
    {"flow-gt/sintel/market_5_final_0009/flow.flo", 1024, 436, 1.0, 1.0},
    {"flow-gt/flyingchairs/0000000-gt.flo", 512, 384, 1.0, 1.0},
    {"flow-gt/kitti/flow_gt.png", 1242, 375, 0.13, 0.20},
};

// Names the fixture in test output and in the ctest names gtest_discover_tests makes.
void PrintTo(const GroundTruth& gt, std::ostream* os) { *os << gt.path; }

class FlowGroundTruth : public ::testing::TestWithParam<GroundTruth> {};
class FloGroundTruth : public ::testing::TestWithParam<GroundTruth> {};

double valid_share(const FlowField& f) {
  if (!f.has_mask()) return 1.0;
  return static_cast<double>(std::count(f.valid.begin(), f.valid.end(), 1)) / static_cast<double>(f.pixel_count());
}

TEST_P(FlowGroundTruth, ReadsWithTheDocumentedSize) {
  const GroundTruth& gt = GetParam();
  NEUFLOW_REQUIRE_FIXTURE(path, gt.path);
  const FlowField f = read_flow(path);
  EXPECT_EQ(f.width, gt.width);
  EXPECT_EQ(f.height, gt.height);
  const double share = valid_share(f);
  EXPECT_GE(share, gt.min_valid_share);
  EXPECT_LE(share, gt.max_valid_share);
  // Plausible motion: finite, within a few hundred pixels, and not all zero.
  double max_magnitude = 0;
  for (std::size_t i = 0; i < f.pixel_count(); ++i) {
    ASSERT_TRUE(std::isfinite(f.uv[2 * i]) && std::isfinite(f.uv[2 * i + 1]));
    if (!f.has_mask() || f.valid[i]) {
      max_magnitude =
          std::max(max_magnitude, std::hypot(static_cast<double>(f.uv[2 * i]), static_cast<double>(f.uv[2 * i + 1])));
    }
  }
  EXPECT_GT(max_magnitude, 0.5);
  EXPECT_LT(max_magnitude, 600.0);
}

TEST_P(FlowGroundTruth, SurvivesConversionToEveryFormat) {
  const GroundTruth& gt = GetParam();
  NEUFLOW_REQUIRE_FIXTURE(path, gt.path);
  const FlowField f = read_flow(path);
  test::TempDir dir;
  for (const char* name : {"c.flo", "c.npy", "c.png"}) {
    SCOPED_TRACE(name);
    write_flow(f, dir / name);
    const FlowField g = read_flow(dir / name);
    ASSERT_EQ(g.width, f.width);
    ASSERT_EQ(g.height, f.height);
    const bool quantized = std::string(name) == "c.png";
    if (!quantized) {
      EXPECT_EQ(g.uv, f.uv);
      EXPECT_EQ(g.valid, f.valid);
    } else {
      // KITTI PNG: 1/64 px steps; every pixel gets a mask entry.
      const FlowMetrics m = compute_metrics(g, f);
      EXPECT_LE(m.epe, 0.5 / 64 * std::sqrt(2.0));
      EXPECT_EQ(g.valid, f.has_mask() ? f.valid : std::vector<std::uint8_t>(f.pixel_count(), 1));
    }
  }
}

TEST_P(FloGroundTruth, MatchesOpenCvsReader) {
  const GroundTruth& gt = GetParam();
  ASSERT_TRUE(std::string(gt.path).ends_with(".flo")) << "kGroundTruth's order changed";
  NEUFLOW_REQUIRE_FIXTURE(path, gt.path);
  const FlowField f = read_flow(path);
  const cv::Mat m = cv::readOpticalFlow(path.string());
  ASSERT_EQ(m.cols, f.width);
  ASSERT_EQ(m.rows, f.height);
  for (int y = 0; y < f.height; ++y) {
    for (int x = 0; x < f.width; ++x) {
      if (!f.is_valid(x, y)) continue;
      ASSERT_EQ(f.u(x, y), m.at<cv::Vec2f>(y, x)[0]);
      ASSERT_EQ(f.v(x, y), m.at<cv::Vec2f>(y, x)[1]);
    }
  }
}

TEST_P(FlowGroundTruth, ComparedWithItselfIsPerfect) {
  const GroundTruth& gt = GetParam();
  NEUFLOW_REQUIRE_FIXTURE(path, gt.path);
  const FlowField f = read_flow(path);
  const FlowMetrics m = compute_metrics(f, f);
  EXPECT_EQ(m.epe, 0.0);
  EXPECT_EQ(m.fl_all, 0.0);
  EXPECT_GT(m.valid_pixels, 0u);
}

std::string fixture_name(const ::testing::TestParamInfo<GroundTruth>& info) {
  std::string name = info.param.path;
  name = name.substr(std::string("flow-gt/").size());
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

INSTANTIATE_TEST_SUITE_P(FlowGt, FlowGroundTruth, ::testing::ValuesIn(kGroundTruth), fixture_name);
// OpenCV's reader speaks only .flo: every entry but the KITTI PNG, which is last.
INSTANTIATE_TEST_SUITE_P(FlowGt, FloGroundTruth,
                         ::testing::ValuesIn(std::begin(kGroundTruth), std::end(kGroundTruth) - 1), fixture_name);

}  // namespace
}  // namespace neuflow::flow
