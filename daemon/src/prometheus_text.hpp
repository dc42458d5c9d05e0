#pragma once
// neuflowd's metrics in the Prometheus text exposition format (version 0.0.4): what the
// metrics endpoint serves. Pure formatting of a snapshot the daemon takes on its main thread,
// so it is tested without a network and the endpoint never touches the streams themselves.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "latency_histogram.hpp"

namespace neuflow::daemon {

// One sink of a stream. Counters count since the daemon started, like the stream's.
struct SinkMetrics {
  std::string sink;           // SinkConfig::name
  std::string kind;           // pipeline::sink_kind(): "files", "shm", "video-file", "rtsp", "udp", "display"
  bool counts_flows = false;  // files and shm sinks count what they write
  std::uint64_t flows_written = 0;
  std::uint64_t bytes_written = 0;  // the flow files' sizes, or the vectors published
  std::uint64_t failures = 0;       // times it failed (or could not be built) and was cut off
};

// One stream as the daemon last saw it. The counters should count since the daemon started,
// summed over the stream's restarts: Prometheus reads any decrease as a counter reset.
struct StreamMetrics {
  std::string stream;  // StreamConfig::name; unique within a snapshot
  std::string state;   // "playing", "starting", "backoff", "stopped", "finished"
  std::uint64_t frames_in = 0;
  std::uint64_t frames_processed = 0;  // frames that left the flow element, with or without flow
  std::uint64_t frames_dropped = 0;
  std::uint64_t flows = 0;  // flow fields delivered to the sinks
  std::uint64_t restarts = 0;
  LatencyCounts inference;         // inference time of each flow
  double uptime_s = 0.0;           // since the stream last reached "playing"; 0 when not playing
  bool stalled = false;            // playing, but no frame has left the flow element for kUpWindowS
  double last_flow_unix_s = 0.0;   // 0: no flow yet
  std::vector<SinkMetrics> sinks;  // in config order
};

// A playing stream is "up" while a frame has left the flow element within this many seconds:
// a stream stuck behind a blocked sink is down long before the stall timeout restarts it.
inline constexpr double kUpWindowS = 5.0;

// The states render_prometheus reports as neuflow_stream_state series, one each per stream.
inline constexpr const char* kStreamStates[] = {"playing", "starting", "backoff", "stopped", "finished"};

// The whole exposition: one family per metric, each with its # HELP and # TYPE once, samples
// ordered as the snapshot. Families of per-stream metrics are left out when there are no
// streams. Inference time is the histogram neuflow_inference_seconds (Prometheus' base unit);
// rates come from rate() over the _total counters, so no gauge holds one.
std::string render_prometheus(const std::vector<StreamMetrics>& streams, double daemon_uptime_s,
                              std::string_view version);

// A label value escaped for the text format: backslash, double quote and line feed become
// \\, \" and \n; everything else (UTF-8 included) is kept.
std::string escape_label_value(std::string_view value);

// A sample value: integers as such, other numbers in the shortest form that reads back
// exactly, and NaN, +Inf, -Inf spelled as the format wants.
std::string format_sample_value(double value);

}  // namespace neuflow::daemon
