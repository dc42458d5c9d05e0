#include "neuflow/eval/scoring.hpp"

#include <cmath>
#include <limits>

namespace neuflow::eval {

namespace {
std::size_t count_of(double ratio, std::size_t pixels) {
  return static_cast<std::size_t>(std::llround(ratio * static_cast<double>(pixels)));
}
}  // namespace

void ScoreAccumulator::add(const flow::FlowMetrics& pair) {
  ++pairs_;
  // A pair without valid pixels adds nothing: the reference would average a NaN into KITTI's
  // EPE, which says less than leaving the empty image out.
  if (pair.valid_pixels == 0) return;
  pixels_ += pair.valid_pixels;
  error_sum_ += pair.epe * static_cast<double>(pair.valid_pixels);
  outliers_ += count_of(pair.fl_all, pair.valid_pixels);
  within1_ += count_of(pair.within_1px, pair.valid_pixels);
  within3_ += count_of(pair.within_3px, pair.valid_pixels);
  within5_ += count_of(pair.within_5px, pair.valid_pixels);
  image_epe_sum_ += pair.epe;
  ++images_scored_;
}

Summary ScoreAccumulator::summary() const {
  Summary s;
  s.pairs = pairs_;
  s.valid_pixels = pixels_;
  if (pixels_ == 0) {
    s.epe = s.fl_all = s.within_1px = s.within_3px = s.within_5px = std::numeric_limits<double>::quiet_NaN();
    return s;
  }
  const auto n = static_cast<double>(pixels_);
  s.epe = aggregation_ == Aggregation::mean_of_images ? image_epe_sum_ / static_cast<double>(images_scored_)
                                                      : error_sum_ / n;
  s.fl_all = static_cast<double>(outliers_) / n;
  s.within_1px = static_cast<double>(within1_) / n;
  s.within_3px = static_cast<double>(within3_) / n;
  s.within_5px = static_cast<double>(within5_) / n;
  return s;
}

}  // namespace neuflow::eval
