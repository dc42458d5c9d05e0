#include "neuflow/flow/metrics.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

#include "field_check.hpp"

namespace neuflow::flow {

MetricCounts& MetricCounts::operator+=(const MetricCounts& other) {
  pixels += other.pixels;
  error_sum += other.error_sum;
  outliers += other.outliers;
  within_1px += other.within_1px;
  within_3px += other.within_3px;
  within_5px += other.within_5px;
  return *this;
}

FlowMetrics metrics_from_counts(const MetricCounts& counts, std::size_t total_pixels) {
  FlowMetrics m;
  m.counts = counts;
  m.valid_pixels = counts.pixels;
  m.total_pixels = total_pixels;
  if (counts.pixels == 0) {
    constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
    m.epe = m.fl_all = m.within_1px = m.within_3px = m.within_5px = kNaN;
    return m;
  }
  const auto n = static_cast<double>(counts.pixels);
  m.epe = counts.error_sum / n;
  m.fl_all = static_cast<double>(counts.outliers) / n;
  m.within_1px = static_cast<double>(counts.within_1px) / n;
  m.within_3px = static_cast<double>(counts.within_3px) / n;
  m.within_5px = static_cast<double>(counts.within_5px) / n;
  return m;
}

FlowMetrics compute_metrics(const FlowField& predicted, const FlowField& ground_truth, const MetricsOptions& options) {
  detail::check_field(predicted, "compute_metrics (prediction)");
  detail::check_field(ground_truth, "compute_metrics (ground truth)");
  if (predicted.width != ground_truth.width || predicted.height != ground_truth.height) {
    throw std::invalid_argument("compute_metrics: prediction is " + std::to_string(predicted.width) + "x" +
                                std::to_string(predicted.height) + " but ground truth is " +
                                std::to_string(ground_truth.width) + "x" + std::to_string(ground_truth.height));
  }

  constexpr double kInf = std::numeric_limits<double>::infinity();
  const std::size_t total = ground_truth.pixel_count();
  MetricCounts c;
  for (std::size_t i = 0; i < total; ++i) {
    if (!ground_truth.valid.empty() && ground_truth.valid[i] == 0) continue;
    if (options.use_predicted_mask && !predicted.valid.empty() && predicted.valid[i] == 0) continue;
    const double gu = ground_truth.uv[2 * i];
    const double gv = ground_truth.uv[2 * i + 1];
    if (!std::isfinite(gu) || !std::isfinite(gv)) continue;
    const double du = predicted.uv[2 * i] - gu;
    const double dv = predicted.uv[2 * i + 1] - gv;
    double error = std::sqrt(du * du + dv * dv);
    if (!std::isfinite(error)) error = kInf;
    const double gt_magnitude = std::sqrt(gu * gu + gv * gv);
    ++c.pixels;
    c.error_sum += error;
    // The KITTI devkit's test is err > 3 && err / |gt| > 0.05; multiplying avoids the 0/0.
    if (error > 3.0 && error > 0.05 * gt_magnitude) ++c.outliers;
    if (error < 1.0) ++c.within_1px;
    if (error < 3.0) ++c.within_3px;
    if (error < 5.0) ++c.within_5px;
  }
  return metrics_from_counts(c, total);
}

}  // namespace neuflow::flow
