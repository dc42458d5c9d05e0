#include "neuflow/eval/scoring.hpp"

namespace neuflow::eval {

void ScoreAccumulator::add(const flow::FlowMetrics& pair) {
  ++pairs_;
  // A pair without valid pixels adds nothing: the reference would average a NaN into KITTI's
  // EPE, which says less than leaving the empty image out.
  if (pair.counts.pixels == 0) return;
  pooled_ += pair.counts;
  image_epe_sum_ += pair.epe;
  ++images_scored_;
}

Summary ScoreAccumulator::summary() const {
  // The ratios of the pooled counts, as flow::compute_metrics makes them for one field.
  const flow::FlowMetrics m = flow::metrics_from_counts(pooled_);
  Summary s{pairs_, pooled_.pixels, m.epe, m.fl_all, m.within_1px, m.within_3px, m.within_5px};
  if (aggregation_ == Aggregation::mean_of_images && images_scored_ > 0) {
    s.epe = image_epe_sum_ / static_cast<double>(images_scored_);
  }
  return s;
}

}  // namespace neuflow::eval
