// Scoring precomputed predictions on the fixtures arranged as each benchmark: ground truth
// as prediction scores EPE 0, ground truth + (3, 4) scores EPE 5 with Fl-all the share of
// pixels whose true flow is under 100 px, and KITTI averages EPE per image.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <string>

#include "layout_fixtures.hpp"
#include "neuflow/eval/errors.hpp"
#include "neuflow/eval/evaluate.hpp"
#include "neuflow/eval/prediction_files.hpp"
#include "neuflow/flow/errors.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::eval {
namespace {

namespace fs = std::filesystem;
using neuflow::test::TempDir;

struct Counts {
  std::size_t valid = 0;
  std::size_t under_100px = 0;  // the (3, 4) offset's Fl outliers: 5 > 0.05 |gt| ⇔ |gt| < 100
};

// Counted straight from the ground-truth files, independently of the code under test.
Counts count_ground_truth(const EvalSet& set) {
  Counts c;
  for (const Pair& pair : set.pairs) {
    const flow::FlowField gt = flow::read_flow(pair.ground_truth);
    for (int y = 0; y < gt.height; ++y) {
      for (int x = 0; x < gt.width; ++x) {
        if (!gt.is_valid(x, y)) continue;
        ++c.valid;
        if (std::hypot(gt.u(x, y), gt.v(x, y)) < 100.0) ++c.under_100px;
      }
    }
  }
  return c;
}

struct Case {
  Dataset dataset;
  const char* fixture;
  fs::path (*arrange)(const fs::path&, const fs::path&);
  const char* extension;  // of the prediction files
};

// Names the case in test listings instead of dumping its bytes.
void PrintTo(const Case& c, std::ostream* os) { *os << to_string(c.dataset); }

class EvalPredictionLayouts : public ::testing::TestWithParam<Case> {};

TEST_P(EvalPredictionLayouts, GroundTruthScoresZeroAndAConstantOffsetScoresItsLength) {
  const Case c = GetParam();
  NEUFLOW_REQUIRE_FIXTURE(fixture, c.fixture);
  TempDir dir;
  const fs::path root = c.arrange(fixture.parent_path(), dir.path() / "dataset");
  for (const EvalSet& set : discover_sets(c.dataset, root)) {
    SCOPED_TRACE(set.name);
    const Counts counts = count_ground_truth(set);
    ASSERT_GT(counts.valid, 0u);

    test::write_predictions(set, dir.path() / "exact", c.extension, test::offset_by(0, 0));
    const SetResult exact = evaluate_set(set, PredictionReader(dir.path() / "exact"));
    EXPECT_EQ(exact.name, set.name);
    EXPECT_EQ(exact.summary.pairs, set.pairs.size());
    EXPECT_EQ(exact.summary.valid_pixels, counts.valid);
    EXPECT_EQ(exact.summary.epe, 0.0);
    EXPECT_EQ(exact.summary.fl_all, 0.0);
    EXPECT_EQ(exact.summary.within_1px, 1.0);

    test::write_predictions(set, dir.path() / "offset", c.extension, test::offset_by(3, 4));
    const SetResult offset = evaluate_set(set, PredictionReader(dir.path() / "offset"));
    // KITTI's ground truth is in 1/64 px steps, so gt + 3 is exact in float32 and the error
    // exactly 5; elsewhere float32 rounding of gt + 3 leaves a few 1e-7 px.
    if (c.dataset == Dataset::kitti) {
      EXPECT_EQ(offset.summary.epe, 5.0);
      EXPECT_EQ(offset.summary.fl_all, static_cast<double>(counts.under_100px) / static_cast<double>(counts.valid));
      EXPECT_EQ(offset.summary.within_5px, 0.0);
    } else {
      EXPECT_NEAR(offset.summary.epe, 5.0, 1e-5);
      EXPECT_NEAR(offset.summary.fl_all, static_cast<double>(counts.under_100px) / static_cast<double>(counts.valid),
                  1e-4);
    }
    EXPECT_EQ(offset.summary.within_1px, 0.0);
    EXPECT_EQ(offset.summary.within_3px, 0.0);
  }
}

INSTANTIATE_TEST_SUITE_P(
    Layouts, EvalPredictionLayouts,
    ::testing::Values(Case{Dataset::sintel, "flow-gt/sintel", test::arrange_sintel, ".flo"},
                      Case{Dataset::kitti, "flow-gt/kitti", test::arrange_kitti, ".png"},
                      Case{Dataset::middlebury, "flow-gt/middlebury", test::arrange_middlebury, ".npy"},
                      Case{Dataset::chairs, "flow-gt/flyingchairs", test::arrange_chairs, ".flo"}),
    [](const ::testing::TestParamInfo<Case>& p) { return std::string(to_string(p.param.dataset)); });

TEST(EvalPredictions, KittiAveragesEpePerImageAndPoolsFlAll) {
  NEUFLOW_REQUIRE_FIXTURE(fixture, "flow-gt/kitti");
  TempDir dir;
  const fs::path root = test::arrange_kitti(fixture.parent_path(), dir.path() / "KITTI");
  // A second pair with the same images and only the bottom rows of the ground truth valid
  // (KITTI's laser data has none in the sky), so the two images have different numbers of
  // valid pixels.
  flow::FlowField bottom = flow::read_flow(root / "training/flow_occ/000000_10.png");
  for (int y = 0; y < 300; ++y) {
    for (int x = 0; x < bottom.width; ++x) bottom.valid[static_cast<std::size_t>(y) * bottom.width + x] = 0;
  }
  flow::write_flow(bottom, root / "training/flow_occ/000001_10.png");
  test::link_file(fixture / "frame1.png", root / "training/image_2/000001_10.png");
  test::link_file(fixture / "frame2.png", root / "training/image_2/000001_11.png");

  const EvalSet set = discover_sets(Dataset::kitti, root).at(0);
  ASSERT_EQ(set.pairs.size(), 2u);
  flow::FlowField first = flow::read_flow(set.pairs[0].ground_truth);
  test::offset_by(3, 4)(first);  // error 5 on every pixel
  fs::create_directories(dir.path() / "pred/image_2");
  flow::write_flow(first, dir.path() / "pred/image_2/000000_10.flo");
  test::offset_by(0, 1)(bottom);  // error 1 on every pixel
  flow::write_flow(bottom, dir.path() / "pred/image_2/000001_10.flo");

  EvalSet first_only = set;
  first_only.pairs.resize(1);
  const Counts counts_first = count_ground_truth(first_only);
  first_only.pairs = {set.pairs[1]};
  const Counts counts_bottom = count_ground_truth(first_only);
  ASSERT_GT(counts_bottom.valid, 0u);
  ASSERT_LT(counts_bottom.valid, counts_first.valid);
  const double all = static_cast<double>(counts_first.valid + counts_bottom.valid);

  const SetResult r = evaluate_set(set, PredictionReader(dir.path() / "pred"));
  EXPECT_EQ(r.summary.epe, 3.0);  // (5 + 1) / 2, where pooling the pixels would weigh image 1 more
  EXPECT_EQ(r.summary.fl_all, static_cast<double>(counts_first.under_100px) / all);
  EXPECT_EQ(r.summary.within_3px, static_cast<double>(counts_bottom.valid) / all);
  EXPECT_EQ(r.summary.within_1px, 0.0);  // an error of exactly 1 px is not under 1 px
  ASSERT_EQ(r.sequences.size(), 2u);
  EXPECT_EQ(r.sequences[0].name, "000000");
  EXPECT_EQ(r.sequences[0].summary.epe, 5.0);
  EXPECT_EQ(r.sequences[1].summary.epe, 1.0);

  // --max-pairs 1: only the first pair.
  EvaluateOptions options;
  options.max_pairs = 1;
  std::size_t calls = 0;
  options.progress = [&](const EvalProgress& p) {
    ++calls;
    EXPECT_EQ(p.total, 1u);
    EXPECT_EQ(p.so_far.epe, 5.0);
  };
  const SetResult one = evaluate_set(set, PredictionReader(dir.path() / "pred"), options);
  EXPECT_EQ(one.summary.pairs, 1u);
  EXPECT_EQ(one.summary.epe, 5.0);
  EXPECT_EQ(calls, 1u);
}

TEST(EvalPredictions, SintelBreaksDownByScene) {
  NEUFLOW_REQUIRE_FIXTURE(fixture, "flow-gt/sintel");
  TempDir dir;
  const fs::path root = test::arrange_sintel(fixture.parent_path(), dir.path() / "Sintel");
  const EvalSet set = discover_sets(Dataset::sintel, root, {SintelPass::clean}).at(0);
  // alley_1 exact, market_5 off by (3, 4): overall the pixel-weighted mean of 0 and 5.
  flow::FlowField alley = flow::read_flow(set.pairs[0].ground_truth);
  fs::create_directories(dir.path() / "pred/clean/alley_1");
  fs::create_directories(dir.path() / "pred/clean/market_5");
  flow::write_flow(alley, dir.path() / "pred/clean/alley_1/frame_0002.flo");
  flow::FlowField market = flow::read_flow(set.pairs[1].ground_truth);
  test::offset_by(3, 4)(market);
  flow::write_flow(market, dir.path() / "pred/clean/market_5/frame_0009.flo");

  const SetResult r = evaluate_set(set, PredictionReader(dir.path() / "pred"));
  ASSERT_EQ(r.sequences.size(), 2u);
  EXPECT_EQ(r.sequences[0].name, "alley_1");
  EXPECT_EQ(r.sequences[0].summary.epe, 0.0);
  EXPECT_EQ(r.sequences[1].name, "market_5");
  EXPECT_NEAR(r.sequences[1].summary.epe, 5.0, 1e-5);
  const double weight =
      static_cast<double>(r.sequences[1].summary.valid_pixels) / static_cast<double>(r.summary.valid_pixels);
  EXPECT_NEAR(r.summary.epe, 5.0 * weight, 1e-5);
}

TEST(EvalPredictions, MissingMalformedAndMisSizedPredictionsAreReported) {
  NEUFLOW_REQUIRE_FIXTURE(fixture, "flow-gt/middlebury");
  TempDir dir;
  const fs::path root = test::arrange_middlebury(fixture.parent_path(), dir.path() / "middlebury");
  const EvalSet set = discover_sets(Dataset::middlebury, root).at(0);
  const PredictionReader reader(dir.path() / "pred");

  try {
    evaluate_set(set, reader);
    FAIL() << "no error for a missing prediction";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::missing_input);
    EXPECT_NE(std::string(e.what()).find("pred/other-data/RubberWhale/frame10.{flo,png,npy}: no prediction"),
              std::string::npos)
        << e.what();
  }

  fs::create_directories(dir.path() / "pred/other-data/RubberWhale");
  std::ofstream(dir.path() / "pred/other-data/RubberWhale/frame10.flo") << "PIEH garbage";
  try {
    evaluate_set(set, reader);
    FAIL() << "no error for a malformed prediction";
  } catch (const flow::FlowFileError& e) {
    EXPECT_EQ(e.kind(), flow::FlowFileError::Kind::malformed);
  }

  // Urban2's ground truth (640×480) given as RubberWhale's prediction (584×388).
  fs::remove(dir.path() / "pred/other-data/RubberWhale/frame10.flo");
  test::link_file(fixture / "Urban2/flow10.flo", dir.path() / "pred/other-data/RubberWhale/frame10.flo");
  try {
    evaluate_set(set, reader);
    FAIL() << "no error for a prediction of the wrong size";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
    EXPECT_NE(std::string(e.what()).find("is 640x480 but its ground truth"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace neuflow::eval
