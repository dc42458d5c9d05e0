#include "latency_histogram.hpp"

#include <algorithm>
#include <cmath>

namespace neuflow::daemon {

void LatencyCounts::add(double seconds) {
  if (!std::isfinite(seconds) || seconds < 0) return;
  // Prometheus buckets are "less than or equal": a time on a bound belongs to that bucket.
  const auto bucket = std::lower_bound(kBounds.begin(), kBounds.end(), seconds) - kBounds.begin();
  ++buckets[static_cast<std::size_t>(bucket)];
  ++count;
  sum += seconds;
}

LatencyCounts& LatencyCounts::operator+=(const LatencyCounts& other) {
  for (std::size_t i = 0; i < buckets.size(); ++i) buckets[i] += other.buckets[i];
  count += other.count;
  sum += other.sum;
  return *this;
}

void LatencyHistogram::record(double seconds) {
  const std::lock_guard guard(lock_);
  counts_.add(seconds);
}

LatencyCounts LatencyHistogram::counts() const {
  const std::lock_guard guard(lock_);
  return counts_;
}

}  // namespace neuflow::daemon
