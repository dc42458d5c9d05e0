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
  std::size_t pixels_ = 0;
  double error_sum_ = 0;  // Σ EPE × valid pixels: the pooled error
  // Counts recovered from the pair's ratios (exact: each ratio is count / pixels in double).
  std::size_t outliers_ = 0, within1_ = 0, within3_ = 0, within5_ = 0;
  double image_epe_sum_ = 0;       // Σ per-image EPE, for mean_of_images
  std::size_t images_scored_ = 0;  // images with at least one valid pixel
};

}  // namespace neuflow::eval
