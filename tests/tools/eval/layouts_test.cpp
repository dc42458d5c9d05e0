// Reading the benchmark layouts: the fixtures arranged as each dataset ships, ROOT given at
// the dataset or at training/, and the errors for layouts that are missing or incomplete.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "layout_fixtures.hpp"
#include "neuflow/eval/errors.hpp"
#include "neuflow/eval/layouts.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::eval {
namespace {

namespace fs = std::filesystem;
using neuflow::test::TempDir;

// The EvalError discover_sets throws, or a failure when it throws none.
EvalError discovery_error(Dataset dataset, const fs::path& root, const LayoutOptions& options = {}) {
  try {
    discover_sets(dataset, root, options);
  } catch (const EvalError& e) {
    return e;
  }
  ADD_FAILURE() << "no EvalError for " << root;
  return EvalError(EvalError::Kind::malformed_input, "none");
}

TEST(EvalLayouts, DatasetNamesRoundTrip) {
  for (Dataset d : {Dataset::sintel, Dataset::kitti, Dataset::middlebury, Dataset::chairs}) {
    EXPECT_EQ(parse_dataset(to_string(d)), d);
  }
  EXPECT_FALSE(parse_dataset("things"));
  EXPECT_FALSE(parse_dataset("Sintel"));
}

TEST(EvalLayouts, SintelHasBothPassesWithConsecutiveFramePairs) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/sintel");
  TempDir dir;
  const fs::path root = test::arrange_sintel(gt.parent_path(), dir.path() / "Sintel");
  const auto sets = discover_sets(Dataset::sintel, root);
  ASSERT_EQ(sets.size(), 2u);
  EXPECT_EQ(sets[0].name, "sintel-clean");
  EXPECT_EQ(sets[1].name, "sintel-final");
  for (const auto& set : sets) {
    EXPECT_EQ(set.pad_mode, PadMode::centred);
    EXPECT_EQ(set.aggregation, Aggregation::pooled_pixels);
    ASSERT_EQ(set.pairs.size(), 2u);
  }
  const Pair& market = sets[1].pairs[1];
  const fs::path training = fs::absolute(root / "training").lexically_normal();
  EXPECT_EQ(market.image0, training / "final/market_5/frame_0009.png");
  EXPECT_EQ(market.image1, training / "final/market_5/frame_0010.png");
  EXPECT_EQ(market.ground_truth, training / "flow/market_5/frame_0009.flo");
  EXPECT_EQ(market.sequence, "market_5");
  EXPECT_EQ(market.key, "final/market_5/frame_0009");
  EXPECT_EQ(sets[0].pairs[0].key, "clean/alley_1/frame_0002");
}

TEST(EvalLayouts, SintelRootMayBeTheTrainingFolderAndOnePass) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/sintel");
  TempDir dir;
  const fs::path root = test::arrange_sintel(gt.parent_path(), dir.path() / "Sintel");
  const auto sets = discover_sets(Dataset::sintel, root / "training/", {SintelPass::final});
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets[0].name, "sintel-final");
  EXPECT_EQ(sets[0].pairs.size(), 2u);
}

TEST(EvalLayouts, SintelFlowWithoutItsNextFrameIsMissingInput) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/sintel");
  TempDir dir;
  const fs::path root = test::arrange_sintel(gt.parent_path(), dir.path() / "Sintel");
  fs::remove(root / "training/final/market_5/frame_0010.png");
  const EvalError e = discovery_error(Dataset::sintel, root, {SintelPass::final});
  EXPECT_EQ(e.kind(), EvalError::Kind::missing_input);
  EXPECT_NE(std::string(e.what()).find("no frame after frame_0009.png"), std::string::npos) << e.what();
  // The first frame missing names the file looked for.
  fs::remove(root / "training/clean/alley_1/frame_0002.png");
  const EvalError first = discovery_error(Dataset::sintel, root, {SintelPass::clean});
  EXPECT_NE(std::string(first.what()).find("clean/alley_1/frame_0002.png: no such image"), std::string::npos)
      << first.what();
}

TEST(EvalLayouts, SintelWithoutTheRequestedPassSaysWhatWasLookedFor) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/sintel");
  TempDir dir;
  const fs::path root = test::arrange_sintel(gt.parent_path(), dir.path() / "Sintel");
  fs::remove_all(root / "training/final");
  EXPECT_EQ(discover_sets(Dataset::sintel, root, {SintelPass::clean}).size(), 1u);
  const EvalError e = discovery_error(Dataset::sintel, root);
  EXPECT_EQ(e.kind(), EvalError::Kind::missing_input);
  const std::string message = e.what();
  EXPECT_NE(message.find("not a MPI-Sintel layout"), std::string::npos) << message;
  EXPECT_NE(message.find("flow/, clean/, final/"), std::string::npos) << message;
  EXPECT_NE(message.find((root / "training").string()), std::string::npos) << message;
}

TEST(EvalLayouts, KittiPairsTheTwoFramesWithFlowOcc) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/kitti");
  TempDir dir;
  const fs::path root = test::arrange_kitti(gt.parent_path(), dir.path() / "KITTI");
  for (const fs::path& given : {root, root / "training"}) {
    const auto sets = discover_sets(Dataset::kitti, given);
    ASSERT_EQ(sets.size(), 1u);
    const EvalSet& set = sets[0];
    EXPECT_EQ(set.name, "kitti");
    EXPECT_EQ(set.pad_mode, PadMode::bottom);
    EXPECT_EQ(set.aggregation, Aggregation::mean_of_images);
    ASSERT_EQ(set.pairs.size(), 1u);
    EXPECT_EQ(set.pairs[0].image1.filename(), "000000_11.png");
    EXPECT_EQ(set.pairs[0].ground_truth.filename(), "000000_10.png");
    EXPECT_EQ(set.pairs[0].ground_truth.parent_path().filename(), "flow_occ");
    EXPECT_EQ(set.pairs[0].key, "image_2/000000_10");
    EXPECT_EQ(set.pairs[0].sequence, "000000");
  }
}

TEST(EvalLayouts, KittiWithoutSecondFrameOrGroundTruthIsMissingInput) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/kitti");
  TempDir dir;
  const fs::path root = test::arrange_kitti(gt.parent_path(), dir.path() / "KITTI");
  fs::remove(root / "training/image_2/000000_11.png");
  EXPECT_NE(std::string(discovery_error(Dataset::kitti, root).what()).find("000000_11.png: no such image"),
            std::string::npos);
  fs::remove(root / "training/flow_occ/000000_10.png");
  const EvalError empty = discovery_error(Dataset::kitti, root);
  EXPECT_EQ(empty.kind(), EvalError::Kind::missing_input);
  EXPECT_NE(std::string(empty.what()).find("no *_10.png ground truth"), std::string::npos) << empty.what();
}

TEST(EvalLayouts, MiddleburyPairsFrame10And11PerSequence) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/middlebury");
  TempDir dir;
  const fs::path root = test::arrange_middlebury(gt.parent_path(), dir.path() / "middlebury");
  // A file that is not flowNN.flo is not ground truth.
  std::ofstream(root / "other-gt-flow/Urban2/readme.flo") << "x";
  const auto sets = discover_sets(Dataset::middlebury, root);
  ASSERT_EQ(sets.size(), 1u);
  ASSERT_EQ(sets[0].pairs.size(), 2u);
  EXPECT_EQ(sets[0].pairs[0].sequence, "RubberWhale");
  EXPECT_EQ(sets[0].pairs[1].key, "other-data/Urban2/frame10");
  EXPECT_EQ(sets[0].pairs[1].image1.filename(), "frame11.png");
  EXPECT_EQ(sets[0].pad_mode, PadMode::centred);
}

TEST(EvalLayouts, ChairsUsesTheValidationSplitWhenPresent) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/flyingchairs");
  TempDir dir;
  const fs::path root = test::arrange_chairs(gt.parent_path(), dir.path() / "FlyingChairs_release");
  auto sets = discover_sets(Dataset::chairs, root);
  ASSERT_EQ(sets.size(), 1u);
  EXPECT_EQ(sets[0].name, "chairs");
  EXPECT_EQ(sets[0].pairs.size(), 2u);
  EXPECT_EQ(sets[0].pairs[0].key, "00001_img1");
  EXPECT_EQ(sets[0].pairs[1].image1.filename(), "00002_img2.ppm");

  std::ofstream(root / "FlyingChairs_train_val.txt") << "1\n2\n";
  for (const fs::path& given : {root, root / "data"}) {
    sets = discover_sets(Dataset::chairs, given);
    ASSERT_EQ(sets.size(), 1u);
    EXPECT_EQ(sets[0].name, "chairs-val");
    ASSERT_EQ(sets[0].pairs.size(), 1u);
    EXPECT_EQ(sets[0].pairs[0].sequence, "00002");
  }
}

TEST(EvalLayouts, ChairsSplitFileThatDoesNotFitIsMalformed) {
  NEUFLOW_REQUIRE_FIXTURE(gt, "flow-gt/flyingchairs");
  TempDir dir;
  const fs::path root = test::arrange_chairs(gt.parent_path(), dir.path() / "chairs");
  std::ofstream(root / "FlyingChairs_train_val.txt") << "1\n2\n2\n";
  EvalError e = discovery_error(Dataset::chairs, root);
  EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
  EXPECT_NE(std::string(e.what()).find("3 labels for 2 *_flow.flo files"), std::string::npos) << e.what();

  std::ofstream(root / "FlyingChairs_train_val.txt") << "1\nvalidation\n";
  e = discovery_error(Dataset::chairs, root);
  EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
  EXPECT_NE(std::string(e.what()).find("entry 2 is 'validation'"), std::string::npos) << e.what();

  std::ofstream(root / "FlyingChairs_train_val.txt") << "1 1\n";
  e = discovery_error(Dataset::chairs, root);
  EXPECT_EQ(e.kind(), EvalError::Kind::missing_input);
  EXPECT_NE(std::string(e.what()).find("no pair for validation"), std::string::npos) << e.what();
}

TEST(EvalLayouts, MissingOrEmptyRootsSayWhatWasLookedFor) {
  TempDir dir;
  const EvalError absent = discovery_error(Dataset::kitti, dir.path() / "nowhere");
  EXPECT_EQ(absent.kind(), EvalError::Kind::missing_input);
  EXPECT_NE(std::string(absent.what()).find("nowhere: no such dataset folder"), std::string::npos) << absent.what();

  fs::create_directories(dir.path() / "empty");
  for (Dataset d : {Dataset::sintel, Dataset::kitti, Dataset::middlebury, Dataset::chairs}) {
    const EvalError e = discovery_error(d, dir.path() / "empty");
    EXPECT_EQ(e.kind(), EvalError::Kind::missing_input) << to_string(d);
    EXPECT_NE(std::string(e.what()).find("not a"), std::string::npos) << e.what();
  }
  const std::string middlebury = discovery_error(Dataset::middlebury, dir.path() / "empty").what();
  EXPECT_NE(middlebury.find("other-data/, other-gt-flow/"), std::string::npos) << middlebury;
  const std::string chairs = discovery_error(Dataset::chairs, dir.path() / "empty").what();
  EXPECT_NE(chairs.find("no *_flow.flo files"), std::string::npos) << chairs;

  // The folders of the layout without any ground truth in them.
  fs::create_directories(dir.path() / "bare/training/image_2");
  fs::create_directories(dir.path() / "bare/training/flow_occ");
  EXPECT_NE(std::string(discovery_error(Dataset::kitti, dir.path() / "bare").what()).find("no *_10.png ground truth"),
            std::string::npos);
}

TEST(EvalLayouts, LayoutInBothRootAndTrainingIsAmbiguous) {
  TempDir dir;
  for (const char* sub : {"image_2", "flow_occ", "training/image_2", "training/flow_occ"}) {
    fs::create_directories(dir.path() / "kitti" / sub);
  }
  const EvalError e = discovery_error(Dataset::kitti, dir.path() / "kitti");
  EXPECT_NE(std::string(e.what()).find("ambiguous KITTI-2015 layout"), std::string::npos) << e.what();
}

}  // namespace
}  // namespace neuflow::eval
