#include "neuflow/flow/metrics.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "test_util.hpp"

namespace neuflow::flow {
namespace {

using test::constant_field;

TEST(Metrics, ConstantOffsetThreeFourGivesEpeFive) {
  const FlowField gt = constant_field(8, 6, 1.f, -2.f);
  const FlowField pred = constant_field(8, 6, 4.f, 2.f);
  const FlowMetrics m = compute_metrics(pred, gt);
  EXPECT_EQ(m.epe, 5.0);
  EXPECT_EQ(m.fl_all, 1.0);  // 5 > 3 and 5 > 5% of |(1, -2)|
  EXPECT_EQ(m.within_1px, 0.0);
  EXPECT_EQ(m.within_3px, 0.0);
  EXPECT_EQ(m.within_5px, 0.0);  // "< 5" is strict
  EXPECT_EQ(m.valid_pixels, 48u);
  EXPECT_EQ(m.total_pixels, 48u);
}

TEST(Metrics, IdenticalFieldsArePerfect) {
  const FlowField gt = constant_field(3, 3, 7.f, 1.f);
  const FlowMetrics m = compute_metrics(gt, gt);
  EXPECT_EQ(m.epe, 0.0);
  EXPECT_EQ(m.fl_all, 0.0);
  EXPECT_EQ(m.within_1px, 1.0);
  EXPECT_EQ(m.within_3px, 1.0);
  EXPECT_EQ(m.within_5px, 1.0);
}

TEST(Metrics, FlAllNeedsBothThreePixelsAndFivePercent) {
  FlowField gt(5, 1);
  FlowField pred(5, 1);
  // |gt| = 100: the 5% threshold is 5 px.
  for (int x = 0; x < 4; ++x) {
    gt.u(x, 0) = 100.f;
    pred.u(x, 0) = 100.f;
  }
  pred.u(0, 0) += 4.f;  // > 3 but < 5% of 100: not an outlier
  pred.v(1, 0) = 6.f;   // > 3 and > 5: outlier
  pred.u(2, 0) -= 2.f;  // < 3: not an outlier
  pred.v(3, 0) = 3.f;   // exactly 3: not an outlier (strict)
  pred.u(4, 0) = 3.5f;  // gt is zero: any error > 3 is an outlier
  const FlowMetrics m = compute_metrics(pred, gt);
  EXPECT_DOUBLE_EQ(m.fl_all, 2.0 / 5.0);
  EXPECT_DOUBLE_EQ(m.epe, (4.0 + 6.0 + 2.0 + 3.0 + 3.5) / 5.0);
  EXPECT_DOUBLE_EQ(m.within_1px, 0.0);
  EXPECT_DOUBLE_EQ(m.within_3px, 1.0 / 5.0);
  EXPECT_DOUBLE_EQ(m.within_5px, 4.0 / 5.0);
}

TEST(Metrics, OnlyGroundTruthValidPixelsCount) {
  FlowField gt = constant_field(4, 1, 0.f, 0.f);
  FlowField pred = constant_field(4, 1, 0.f, 0.f);
  gt.valid = {1, 0, 1, 0};
  pred.u(1, 0) = 1000.f;  // invalid in gt: ignored
  pred.u(2, 0) = 2.f;
  const FlowMetrics m = compute_metrics(pred, gt);
  EXPECT_EQ(m.valid_pixels, 2u);
  EXPECT_EQ(m.total_pixels, 4u);
  EXPECT_EQ(m.epe, 1.0);
  EXPECT_EQ(m.within_1px, 0.5);
}

TEST(Metrics, PredictedMaskIsIgnoredUnlessAsked) {
  const FlowField gt = constant_field(2, 1, 0.f, 0.f);
  FlowField pred = constant_field(2, 1, 0.f, 0.f);
  pred.u(1, 0) = 4.f;
  pred.valid = {1, 0};
  EXPECT_EQ(compute_metrics(pred, gt).epe, 2.0);
  EXPECT_EQ(compute_metrics(pred, gt).valid_pixels, 2u);
  MetricsOptions options;
  options.use_predicted_mask = true;
  const FlowMetrics m = compute_metrics(pred, gt, options);
  EXPECT_EQ(m.epe, 0.0);
  EXPECT_EQ(m.valid_pixels, 1u);
}

TEST(Metrics, NoValidPixelGivesNaNRatios) {
  FlowField gt = constant_field(2, 2, 0.f, 0.f);
  gt.valid.assign(4, 0);
  const FlowMetrics m = compute_metrics(gt, gt);
  EXPECT_EQ(m.valid_pixels, 0u);
  EXPECT_TRUE(std::isnan(m.epe));
  EXPECT_TRUE(std::isnan(m.fl_all));
  EXPECT_TRUE(std::isnan(m.within_3px));
}

TEST(Metrics, NonFinitePredictionIsAnInfiniteError) {
  const FlowField gt = constant_field(2, 1, 0.f, 0.f);
  FlowField pred = constant_field(2, 1, 0.f, 0.f);
  pred.v(0, 0) = std::numeric_limits<float>::quiet_NaN();
  const FlowMetrics m = compute_metrics(pred, gt);
  EXPECT_TRUE(std::isinf(m.epe));
  EXPECT_EQ(m.fl_all, 0.5);
  EXPECT_EQ(m.within_1px, 0.5);
}

TEST(Metrics, SizeMismatchIsAClearError) {
  try {
    compute_metrics(FlowField(4, 3), FlowField(3, 4));
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("prediction is 4x3 but ground truth is 3x4"), std::string::npos) << e.what();
  }
  FlowField broken(2, 2);
  broken.uv.pop_back();
  EXPECT_THROW(compute_metrics(broken, FlowField(2, 2)), std::invalid_argument);
}

// Pooled counts give the measures of the pixels together: the same as one field holding both.
TEST(Metrics, PooledCountsEqualTheMetricsOfTheFieldsTogether) {
  const FlowField gt_a = constant_field(4, 2, 1.f, 0.f), pred_a = constant_field(4, 2, 4.f, 4.f);   // error 5
  const FlowField gt_b = constant_field(2, 2, 0.f, 0.f), pred_b = constant_field(2, 2, 0.5f, 0.f);  // error 0.5
  MetricCounts pooled = compute_metrics(pred_a, gt_a).counts;
  pooled += compute_metrics(pred_b, gt_b).counts;
  FlowField gt_ab(12, 1), pred_ab(12, 1);
  for (int i = 0; i < 12; ++i) {
    const bool a = i < 8;
    gt_ab.uv[2 * i] = a ? 1.f : 0.f;
    pred_ab.uv[2 * i] = a ? 4.f : 0.5f;
    pred_ab.uv[2 * i + 1] = a ? 4.f : 0.f;
  }
  const FlowMetrics together = compute_metrics(pred_ab, gt_ab);
  const FlowMetrics from_counts = metrics_from_counts(pooled);
  EXPECT_EQ(from_counts.valid_pixels, 12u);
  EXPECT_DOUBLE_EQ(from_counts.epe, together.epe);
  EXPECT_DOUBLE_EQ(from_counts.epe, (8 * 5.0 + 4 * 0.5) / 12);
  EXPECT_DOUBLE_EQ(from_counts.fl_all, together.fl_all);
  EXPECT_DOUBLE_EQ(from_counts.within_1px, together.within_1px);
  EXPECT_DOUBLE_EQ(from_counts.within_5px, together.within_5px);
  EXPECT_TRUE(std::isnan(metrics_from_counts(MetricCounts{}).epe));
}

}  // namespace
}  // namespace neuflow::flow
