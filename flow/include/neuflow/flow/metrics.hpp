#pragma once
// The standard accuracy measures of a predicted flow against ground truth.
#include <cstddef>

#include "neuflow/flow/flow_field.hpp"

namespace neuflow::flow {

// What the measures are made of, over the evaluated pixels: sums and counts, so that several
// fields can be pooled exactly (benchmark sets add up their pairs' counts).
struct MetricCounts {
  std::size_t pixels = 0;      // evaluated
  double error_sum = 0;        // Σ end-point error, px
  std::size_t outliers = 0;    // KITTI Fl: error > 3 px and > 5% of |gt|
  std::size_t within_1px = 0;  // error < 1 px
  std::size_t within_3px = 0;
  std::size_t within_5px = 0;

  MetricCounts& operator+=(const MetricCounts& other);
};

struct FlowMetrics {
  double epe = 0;         // mean end-point error |pred − gt| in px
  double fl_all = 0;      // KITTI Fl-all: share with error > 3 px and > 5% of |gt|, in [0, 1]
  double within_1px = 0;  // share of pixels with error < 1 px, in [0, 1]
  double within_3px = 0;
  double within_5px = 0;
  std::size_t valid_pixels = 0;  // pixels that were evaluated
  std::size_t total_pixels = 0;  // width × height
  MetricCounts counts;           // what the ratios above are made of
};

// The measures of pooled counts: every ratio over `counts.pixels`, NaN when it is 0.
// `total_pixels` is only carried over.
FlowMetrics metrics_from_counts(const MetricCounts& counts, std::size_t total_pixels = 0);

struct MetricsOptions {
  // Ground truth decides which pixels count. By default the prediction's own mask is
  // ignored and its values are taken as they are (a method is scored on every pixel the
  // ground truth knows, as the benchmarks do). Set this to evaluate only pixels that are
  // valid in both.
  bool use_predicted_mask = false;
};

// Evaluates pixels valid in gt's mask whose gt values are finite. A non-finite prediction
// at such a pixel counts as an infinite error: EPE becomes infinite and the pixel is an
// Fl outlier, which shows the problem instead of hiding it. With no pixel to evaluate every
// ratio (epe, fl_all, within_*) is NaN. Throws std::invalid_argument when the sizes differ
// or a field is inconsistent.
FlowMetrics compute_metrics(const FlowField& predicted, const FlowField& ground_truth,
                            const MetricsOptions& options = {});

}  // namespace neuflow::flow
