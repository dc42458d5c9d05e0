#pragma once
// Inference times as a Prometheus histogram: fixed buckets in seconds (from a fast GPU's tens
// of milliseconds to a small board's seconds), recorded from the streaming thread that pushes
// the flows and read by the metrics scrape on the main thread.
#include <array>
#include <cstdint>
#include <mutex>

namespace neuflow::daemon {

struct LatencyCounts {
  static constexpr std::array<double, 12> kBounds = {0.01, 0.025, 0.05, 0.1, 0.25, 0.5, 1, 2.5, 5, 10, 30, 60};
  std::array<std::uint64_t, kBounds.size() + 1> buckets{};  // per bucket, not cumulative; the last is +Inf
  std::uint64_t count = 0;
  double sum = 0;  // seconds

  void add(double seconds);
  LatencyCounts& operator+=(const LatencyCounts& other);
};

class LatencyHistogram {
 public:
  explicit LatencyHistogram(LatencyCounts start = {}) : counts_(start) {}
  void record(double seconds);
  LatencyCounts counts() const;

 private:
  mutable std::mutex lock_;
  LatencyCounts counts_;
};

}  // namespace neuflow::daemon
