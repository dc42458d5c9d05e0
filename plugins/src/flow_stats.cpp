#include "flow_stats.hpp"

#include <cmath>

namespace neuflow::gst {

void FlowStats::restart(Clock::time_point now) {
  *this = FlowStats{};
  started_ = last_message_ = now;
}

bool FlowStats::frame_out(bool with_flow, double seconds) {
  ++processed_;
  if (!with_flow) return false;
  ++flows_;
  inference_seconds_ += seconds;
  // The first flows pay for warm-up; the estimate follows recent ones.
  latency_estimate_ = latency_estimate_ == 0 ? seconds : 0.75 * latency_estimate_ + 0.25 * seconds;
  if (announced_latency_ == 0 || std::abs(latency_estimate_ - announced_latency_) > 0.2 * announced_latency_) {
    announced_latency_ = latency_estimate_;
    return true;
  }
  return false;
}

bool FlowStats::message_due(Clock::time_point now, unsigned interval_ms) {
  if (interval_ms == 0 || now - last_message_ < std::chrono::milliseconds(interval_ms)) return false;
  last_message_ = now;
  return true;
}

double FlowStats::mean_latency_ms() const {
  return flows_ ? 1e3 * inference_seconds_ / static_cast<double>(flows_) : 0.0;
}

double FlowStats::processing_rate(Clock::time_point now) const {
  const double elapsed = processed_ ? std::chrono::duration<double>(now - started_).count() : 0.0;
  return elapsed > 0 ? static_cast<double>(processed_) / elapsed : 0.0;
}

}  // namespace neuflow::gst
