// `neuflow eval` running the network: the fixture checkpoint (random weights) on a small
// crop of the KITTI pair at an odd size, so both paddings and the crop back are exercised.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "layout_fixtures.hpp"
#include "neuflow/eval/errors.hpp"
#include "neuflow/eval/evaluate.hpp"
#include "neuflow/eval/model_predictor.hpp"
#include "neuflow/flow/flow_io.hpp"
#include "support/fixtures.hpp"
#include "support/temp_dir.hpp"

namespace neuflow::eval {
namespace {

namespace fs = std::filesystem;

// 101×70 (padded to 112×80) from the middle of the KITTI pair, as a KITTI layout.
constexpr int kX = 500, kY = 150, kW = 101, kH = 70;

fs::path arrange_small_kitti(const fs::path& kitti, const fs::path& root) {
  const cv::Rect window(kX, kY, kW, kH);
  fs::create_directories(root / "training/image_2");
  fs::create_directories(root / "training/flow_occ");
  cv::imwrite((root / "training/image_2/000000_10.png").string(), cv::imread((kitti / "frame1.png").string())(window));
  cv::imwrite((root / "training/image_2/000000_11.png").string(), cv::imread((kitti / "frame2.png").string())(window));
  const flow::FlowField gt = flow::read_flow(kitti / "flow_gt.png");
  flow::FlowField crop(kW, kH);
  crop.valid.assign(crop.pixel_count(), 0);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      crop.u(x, y) = gt.u(x + kX, y + kY);
      crop.v(x, y) = gt.v(x + kX, y + kY);
      crop.valid[static_cast<std::size_t>(y) * kW + x] = gt.is_valid(x + kX, y + kY) ? 1 : 0;
    }
  }
  flow::write_flow(crop, root / "training/flow_occ/000000_10.png");
  return root;
}

bool all_finite(const flow::FlowField& f) {
  for (float x : f.uv) {
    if (!std::isfinite(x)) return false;
  }
  return true;
}

class EvalModel : public ::testing::Test {
 protected:
  void SetUp() override {
    auto dir = ::neuflow::test::fixtures_dir();
    if (!dir || !fs::exists(*dir / "neuflow-v2-seed0/checkpoint.pth")) return;
    model_ = model::FlowModel::load(*dir / "neuflow-v2-seed0/checkpoint.pth");
  }
  model::SessionOptions tiny() const {
    model::SessionOptions o;
    o.iterations = {1, 1};
    o.threads = 1;  // one thread: bit-identical runs, and kind to a shared machine
    return o;
  }
  std::shared_ptr<const model::FlowModel> model_;
};

TEST_F(EvalModel, RunsEndToEndOnAnOddSizedKittiPair) {
  NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
  NEUFLOW_REQUIRE_FIXTURE(kitti, "flow-gt/kitti");
  neuflow::test::TempDir dir;
  const fs::path root = arrange_small_kitti(kitti, dir.path() / "KITTI");
  const EvalSet set = discover_sets(Dataset::kitti, root).at(0);
  ModelPredictor predictor(model_, tiny());
  const SetResult r = evaluate_set(set, [&](const EvalSet& s, const Pair& p) { return predictor(s, p); });
  EXPECT_EQ(r.summary.pairs, 1u);
  EXPECT_GT(r.summary.valid_pixels, 0u);
  EXPECT_TRUE(std::isfinite(r.summary.epe)) << r.summary.epe;
  EXPECT_GT(r.summary.epe, 0.0);  // random weights do not guess KITTI's flow
  EXPECT_GE(r.summary.fl_all, 0.0);
  EXPECT_LE(r.summary.fl_all, 1.0);
  EXPECT_LE(r.summary.within_1px, r.summary.within_3px);
  EXPECT_LE(r.summary.within_3px, r.summary.within_5px);
}

TEST_F(EvalModel, CentredPaddingMatchesTheSessionsOwnAndBottomPaddingDiffers) {
  NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
  NEUFLOW_REQUIRE_FIXTURE(kitti, "flow-gt/kitti");
  const cv::Rect window(kX, kY, kW, kH);
  const cv::Mat image0 = read_bgr_image(kitti / "frame1.png")(window).clone();
  const cv::Mat image1 = read_bgr_image(kitti / "frame2.png")(window).clone();

  ModelPredictor predictor(model_, tiny());
  const flow::FlowField centred = predictor.predict(image0, image1, PadMode::centred);
  const flow::FlowField bottom = predictor.predict(image0, image1, PadMode::bottom);
  ASSERT_EQ(centred.width, kW);
  ASSERT_EQ(centred.height, kH);
  ASSERT_EQ(bottom.width, kW);
  ASSERT_EQ(bottom.height, kH);
  EXPECT_TRUE(all_finite(centred));
  EXPECT_TRUE(all_finite(bottom));

  // A session given the unpadded images pads them centred itself (pw // 2 = 5 left,
  // ph // 2 = 5 on top): the same network input, so the same flow to the bit. A crop off by
  // a pixel would not be.
  model::SessionOptions options;
  options.iterations = {1, 1};
  options.threads = 1;
  model::FlowSession session(model_, options);
  const auto view = [](const cv::Mat& m) {
    return model::ImageView{m.data, m.cols, m.rows, static_cast<std::ptrdiff_t>(m.step[0]), model::ChannelOrder::bgr};
  };
  const flow::FlowField reference = session.compute(view(image0), view(image1));
  EXPECT_EQ(centred.uv, reference.uv);
  EXPECT_NE(bottom.uv, reference.uv);  // the KITTI padding feeds the network another image
}

TEST_F(EvalModel, ChannelOrderChangesWhatTheNetworkSees) {
  NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
  NEUFLOW_REQUIRE_FIXTURE(frame0, "neuflow-v2-seed0/frame0.png");
  const cv::Mat a = read_bgr_image(frame0)(cv::Rect(0, 0, 64, 48)).clone();
  const cv::Mat b = read_bgr_image(frame0.parent_path() / "frame1.png")(cv::Rect(0, 0, 64, 48)).clone();
  model::SessionOptions bgr = tiny();
  bgr.network_order = model::ChannelOrder::bgr;
  ModelPredictor as_rgb(model_, tiny()), as_bgr(model_, bgr);
  // Feeding BGR is the same as feeding RGB images whose channels were swapped.
  cv::Mat a_swapped, b_swapped;
  cv::cvtColor(a, a_swapped, cv::COLOR_BGR2RGB);
  cv::cvtColor(b, b_swapped, cv::COLOR_BGR2RGB);
  EXPECT_EQ(as_bgr.predict(a, b, PadMode::centred).uv, as_rgb.predict(a_swapped, b_swapped, PadMode::centred).uv);
  EXPECT_NE(as_bgr.predict(a, b, PadMode::centred).uv, as_rgb.predict(a, b, PadMode::centred).uv);
}

TEST_F(EvalModel, UnusableImagesAreMalformedInput) {
  NEUFLOW_REQUIRE_FIXTURE(checkpoint, "neuflow-v2-seed0/checkpoint.pth");
  NEUFLOW_REQUIRE_FIXTURE(frame0, "neuflow-v2-seed0/frame0.png");
  ModelPredictor predictor(model_, tiny());
  const cv::Mat big(48, 64, CV_8UC3, cv::Scalar(1, 2, 3)), other(40, 64, CV_8UC3, cv::Scalar(1, 2, 3));
  try {
    predictor.predict(big, other, PadMode::centred);
    FAIL() << "no error for images of different sizes";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
    EXPECT_NE(std::string(e.what()).find("64x48 and 64x40"), std::string::npos) << e.what();
  }
  // Below the network's 32×32 minimum even after padding to 16: 20×10 pads to 32×16.
  const cv::Mat tiny_image(10, 20, CV_8UC3, cv::Scalar(0, 0, 0));
  try {
    predictor.predict(tiny_image, tiny_image, PadMode::centred);
    FAIL() << "no error for an image too small for the network";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
    EXPECT_NE(std::string(e.what()).find("cannot run the network on a 20x10 pair"), std::string::npos) << e.what();
  }

  neuflow::test::TempDir dir;
  std::ofstream(dir.path() / "not-an-image.png") << "text";
  try {
    read_bgr_image(dir.path() / "not-an-image.png");
    FAIL() << "no error for an undecodable image";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::malformed_input);
  }
  try {
    read_bgr_image(dir.path() / "absent.png");
    FAIL() << "no error for a missing image";
  } catch (const EvalError& e) {
    EXPECT_EQ(e.kind(), EvalError::Kind::missing_input);
    EXPECT_NE(std::string(e.what()).find("absent.png: no such image file"), std::string::npos);
  }
}

}  // namespace
}  // namespace neuflow::eval
