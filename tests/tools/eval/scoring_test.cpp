// Combining pairs into a set's numbers: pooled over pixels (Sintel, Chairs, Middlebury) or
// EPE averaged per image (KITTI), on fields whose errors are known exactly.
#include <gtest/gtest.h>

#include <cmath>

#include "neuflow/eval/scoring.hpp"
#include "neuflow/flow/metrics.hpp"

namespace neuflow::eval {
namespace {

// A w×h ground truth of (gt_u, 0) and a prediction off by (error, 0) on its first `valid`
// pixels; the rest of the ground truth is invalid.
flow::FlowMetrics pair_with_error(int w, int h, int valid, float gt_u, float error) {
  flow::FlowField gt(w, h), predicted(w, h);
  gt.valid.assign(gt.pixel_count(), 0);
  for (int i = 0; i < valid; ++i) gt.valid[static_cast<std::size_t>(i)] = 1;
  for (std::size_t i = 0; i < gt.pixel_count(); ++i) {
    gt.uv[2 * i] = gt_u;
    predicted.uv[2 * i] = gt_u + error;
  }
  return flow::compute_metrics(predicted, gt);
}

TEST(EvalScoring, PooledPixelsWeighsPairsByTheirValidPixels) {
  ScoreAccumulator acc(Aggregation::pooled_pixels);
  acc.add(pair_with_error(4, 4, 12, 10.f, 4.f));  // 12 px off by 4: Fl outliers (4 > 3, 4 > 0.5)
  acc.add(pair_with_error(4, 4, 4, 10.f, 0.5f));  // 4 px off by 0.5
  const Summary s = acc.summary();
  EXPECT_EQ(s.pairs, 2u);
  EXPECT_EQ(s.valid_pixels, 16u);
  EXPECT_DOUBLE_EQ(s.epe, (12 * 4.0 + 4 * 0.5) / 16);  // 3.125, not the mean of images (2.25)
  EXPECT_DOUBLE_EQ(s.fl_all, 12.0 / 16);
  EXPECT_DOUBLE_EQ(s.within_1px, 4.0 / 16);
  EXPECT_DOUBLE_EQ(s.within_3px, 4.0 / 16);
  EXPECT_DOUBLE_EQ(s.within_5px, 1.0);
}

TEST(EvalScoring, MeanOfImagesAveragesEpePerImageButPoolsTheRates) {
  ScoreAccumulator acc(Aggregation::mean_of_images);
  acc.add(pair_with_error(4, 4, 12, 10.f, 4.f));
  acc.add(pair_with_error(4, 4, 4, 10.f, 0.5f));
  const Summary s = acc.summary();
  EXPECT_DOUBLE_EQ(s.epe, (4.0 + 0.5) / 2);
  EXPECT_DOUBLE_EQ(s.fl_all, 12.0 / 16);
  EXPECT_DOUBLE_EQ(s.within_1px, 4.0 / 16);
}

TEST(EvalScoring, FlAllNeedsBothThreePixelsAndFivePercent) {
  ScoreAccumulator acc(Aggregation::pooled_pixels);
  acc.add(pair_with_error(2, 2, 4, 100.f, 4.f));  // 4 px is < 5% of 100: not an outlier
  acc.add(pair_with_error(2, 2, 4, 60.f, 4.f));   // 4 px is > 5% of 60 and > 3 px: outliers
  acc.add(pair_with_error(2, 2, 4, 0.f, 2.9f));   // below 3 px: not an outlier even for |gt| = 0
  EXPECT_DOUBLE_EQ(acc.summary().fl_all, 4.0 / 12);
}

TEST(EvalScoring, PairsWithoutValidPixelsCountButDoNotScore) {
  ScoreAccumulator acc(Aggregation::mean_of_images);
  acc.add(pair_with_error(2, 2, 0, 1.f, 1.f));
  Summary s = acc.summary();
  EXPECT_EQ(s.pairs, 1u);
  EXPECT_EQ(s.valid_pixels, 0u);
  EXPECT_TRUE(std::isnan(s.epe));
  EXPECT_TRUE(std::isnan(s.fl_all));
  acc.add(pair_with_error(2, 2, 4, 1.f, 2.f));
  s = acc.summary();
  EXPECT_EQ(s.pairs, 2u);
  EXPECT_DOUBLE_EQ(s.epe, 2.0);  // the empty image does not drag the per-image mean down
}

TEST(EvalScoring, NonFinitePredictionMakesEpeInfinite) {
  flow::FlowField gt(2, 1), predicted(2, 1);
  predicted.uv[0] = std::nanf("");
  ScoreAccumulator acc(Aggregation::pooled_pixels);
  acc.add(flow::compute_metrics(predicted, gt));
  const Summary s = acc.summary();
  EXPECT_TRUE(std::isinf(s.epe));
  EXPECT_DOUBLE_EQ(s.within_1px, 0.5);
}

TEST(EvalScoring, EmptyAccumulatorIsNotANumber) {
  const Summary s = ScoreAccumulator(Aggregation::pooled_pixels).summary();
  EXPECT_EQ(s.pairs, 0u);
  EXPECT_TRUE(std::isnan(s.epe));
  EXPECT_TRUE(std::isnan(s.within_5px));
}

}  // namespace
}  // namespace neuflow::eval
