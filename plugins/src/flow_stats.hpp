#pragma once
// The neuflow element's counters and its latency estimate, as plain C++ (no GStreamer), so the
// rules are tested on their own. Not thread-safe: the element guards one instance with a lock.
#include <chrono>
#include <cstdint>

namespace neuflow::gst {

class FlowStats {
 public:
  using Clock = std::chrono::steady_clock;

  // Everything back to zero; the rate is measured from `now`.
  void restart(Clock::time_point now);

  void frame_in() { ++frames_in_; }
  void dropped(std::uint64_t frames) { dropped_ += frames; }

  // A frame left the element, with a flow computed in `seconds` or without one (the first
  // frame of a stream). Returns true when the latency estimate first appears or moves by more
  // than a fifth either way: the pipeline should then be told to ask for it again.
  bool frame_out(bool with_flow, double seconds);

  // True (and the interval restarts) when `interval_ms` has passed since the last time.
  bool message_due(Clock::time_point now, unsigned interval_ms);

  std::uint64_t frames_in() const { return frames_in_; }
  std::uint64_t processed() const { return processed_; }  // frames that left, with or without flow
  std::uint64_t flows() const { return flows_; }          // frames that left with flow
  std::uint64_t frames_dropped() const { return dropped_; }
  double mean_latency_ms() const;                       // mean inference time of the flows
  double processing_rate(Clock::time_point now) const;  // frames out per second since restart
  // What latency to report per frame: a moving average of recent inference times, the value
  // last announced (0 before the first flow).
  double announced_latency() const { return announced_latency_; }

 private:
  std::uint64_t frames_in_ = 0;
  std::uint64_t processed_ = 0;
  std::uint64_t flows_ = 0;
  std::uint64_t dropped_ = 0;
  double inference_seconds_ = 0;  // sum over flows
  double latency_estimate_ = 0;
  double announced_latency_ = 0;
  Clock::time_point started_{};
  Clock::time_point last_message_{};
};

}  // namespace neuflow::gst
