// The reference evaluation's padding (RAFT/NeuFlow-V2 InputPadder with factor 16), checked
// against sizes worked out by hand, and the crop that undoes it.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <stdexcept>

#include "neuflow/eval/padding.hpp"

namespace neuflow::eval {
namespace {

TEST(EvalPadding, SintelFrameIsPaddedEvenlyTopAndBottom) {
  // 1024×436: width already a multiple; 448 − 436 = 12 rows, 6 above and 6 below.
  EXPECT_EQ(reference_padding(1024, 436, PadMode::centred), (Padding{0, 0, 6, 6}));
}

TEST(EvalPadding, KittiFrameIsPaddedAtTheBottomAndCentredAcross) {
  // 1242×375: 1248 − 1242 = 6 columns, 3 each side; 384 − 375 = 9 rows, all at the bottom.
  EXPECT_EQ(reference_padding(1242, 375, PadMode::bottom), (Padding{3, 3, 0, 9}));
  // The same frame centred: the odd row goes to the bottom (ph // 2 = 4 above).
  EXPECT_EQ(reference_padding(1242, 375, PadMode::centred), (Padding{3, 3, 4, 5}));
}

TEST(EvalPadding, OddPaddingPutsTheExtraPixelRightAndBottom) {
  // 101×70: 112 − 101 = 11 columns → 5 left, 6 right; 80 − 70 = 10 rows.
  EXPECT_EQ(reference_padding(101, 70, PadMode::centred), (Padding{5, 6, 5, 5}));
  EXPECT_EQ(reference_padding(101, 70, PadMode::bottom), (Padding{5, 6, 0, 10}));
  // 33×17: 15 columns → 7 left, 8 right; 15 rows → 7 above, 8 below (centred).
  EXPECT_EQ(reference_padding(33, 17, PadMode::centred), (Padding{7, 8, 7, 8}));
  EXPECT_EQ(reference_padding(33, 17, PadMode::bottom), (Padding{7, 8, 0, 15}));
}

TEST(EvalPadding, MultiplesNeedNoPadding) {
  EXPECT_EQ(reference_padding(512, 384, PadMode::centred), Padding{});
  EXPECT_EQ(reference_padding(512, 384, PadMode::bottom), Padding{});
  // Another factor (the reference's default of 8) follows the same rule.
  EXPECT_EQ(reference_padding(584, 388, PadMode::centred, 8), (Padding{0, 0, 2, 2}));
}

TEST(EvalPadding, RejectsNonPositiveSizes) {
  EXPECT_THROW(reference_padding(0, 10, PadMode::centred), std::invalid_argument);
  EXPECT_THROW(reference_padding(10, -1, PadMode::bottom), std::invalid_argument);
  EXPECT_THROW(reference_padding(10, 10, PadMode::bottom, 0), std::invalid_argument);
}

TEST(EvalPadding, PadImageReplicatesTheEdges) {
  // 3×2 single-channel image with distinct values; pad left 1, right 2, top 0, bottom 1.
  const cv::Mat image = (cv::Mat_<unsigned char>(2, 3) << 1, 2, 3, 4, 5, 6);
  const cv::Mat padded = pad_image(image, Padding{1, 2, 0, 1});
  ASSERT_EQ(padded.cols, 6);
  ASSERT_EQ(padded.rows, 3);
  const cv::Mat expected = (cv::Mat_<unsigned char>(3, 6) << 1, 1, 2, 3, 3, 3,  //
                            4, 4, 5, 6, 6, 6,                                   //
                            4, 4, 5, 6, 6, 6);
  EXPECT_EQ(cv::countNonZero(padded != expected), 0);
}

TEST(EvalPadding, CropFlowTakesTheOriginalWindowWithItsMask) {
  // A 5×4 field whose u encodes x and v encodes y; crop left 1, right 2, top 1, bottom 0.
  flow::FlowField padded(5, 4);
  padded.valid.assign(padded.pixel_count(), 1);
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 5; ++x) {
      padded.u(x, y) = static_cast<float>(x);
      padded.v(x, y) = static_cast<float>(10 * y);
    }
  }
  padded.valid[2 * 5 + 1] = 0;  // (1, 2) → (0, 1) after the crop
  const flow::FlowField out = crop_flow(padded, Padding{1, 2, 1, 0});
  ASSERT_EQ(out.width, 2);
  ASSERT_EQ(out.height, 3);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 2; ++x) {
      EXPECT_EQ(out.u(x, y), static_cast<float>(x + 1));
      EXPECT_EQ(out.v(x, y), static_cast<float>(10 * (y + 1)));
      EXPECT_EQ(out.is_valid(x, y), !(x == 0 && y == 1));
    }
  }
}

TEST(EvalPadding, CropFlowRejectsPaddingLargerThanTheField) {
  const flow::FlowField field(4, 4);
  EXPECT_THROW(crop_flow(field, Padding{2, 2, 0, 0}), std::invalid_argument);
  EXPECT_THROW(crop_flow(field, Padding{0, 0, 3, 1}), std::invalid_argument);
  EXPECT_THROW(crop_flow(field, Padding{-1, 0, 0, 0}), std::invalid_argument);
}

}  // namespace
}  // namespace neuflow::eval
