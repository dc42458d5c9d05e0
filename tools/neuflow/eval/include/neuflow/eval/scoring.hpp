#pragma once
// Combining per-pair accuracy into a set's numbers, by the set's Aggregation (layouts.hpp).
#include <cstddef>

#include "neuflow/eval/layouts.hpp"
#include "neuflow/flow/metrics.hpp"

namespace neuflow::eval {

struct Summary {
  std::size_t pairs = 0;         // pairs added
  std::size_t valid_pixels = 0;  // ground-truth pixels scored, over all pairs
  // As in FlowMetrics: px for EPE, fractions in [0, 1] for the rest; NaN when no pixel was
  // scored, EPE infinite when a prediction was not finite at a scored pixel.
  double epe = 0, fl_all = 0, within_1px = 0, within_3px = 0, within_5px = 0;
};

class ScoreAccumulator {
 public:
  explicit ScoreAccumulator(Aggregation aggregation) : aggregation_(aggregation) {}

  // One pair's metrics (compute_metrics of its prediction against its ground truth).
  void add(const flow::FlowMetrics& pair);
  Summary summary() const;

 private:
  Aggregation aggregation_;
  std::size_t pairs_ = 0;
  flow::MetricCounts pooled_;      // every pair's pixels together
  double image_epe_sum_ = 0;       // Σ per-image EPE, for mean_of_images
  std::size_t images_scored_ = 0;  // images with at least one valid pixel
};

}  // namespace neuflow::eval
