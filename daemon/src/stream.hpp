#pragma once
// One configured stream, supervised: it builds its pipeline, watches the bus, restarts the
// pipeline with exponential backoff when the source or the flow element fails (or stops
// delivering frames), cuts off a failing sink while others remain, and stops cleanly with
// EOS so files are finalized. Everything here runs on the daemon's main loop (main thread);
// GStreamer's threads only ever touch the graph's sink-failure marks.
#include <gst/gst.h>

#include <chrono>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "config.hpp"
#include "latency_histogram.hpp"
#include "neuflow/pipeline/stream_graph.hpp"

namespace neuflow::daemon {

using pipeline::SinkBranch;
using pipeline::StreamGraph;
using pipeline::UnbuiltSink;

enum class StreamState { idle, starting, playing, backoff, stopping, stopped, finished };
const char* to_string(StreamState state);

struct StreamSnapshot {
  std::string name;
  StreamState state = StreamState::idle;
  std::uint64_t frames_in = 0;  // over all runs of the pipeline
  std::uint64_t frames_processed = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t flows = 0;  // frames that left with a flow
  std::uint64_t restarts = 0;
  LatencyCounts inference;  // every flow's inference time, over all runs
  double seconds_in_state = 0;
  double retry_in_s = 0;              // backoff only
  double seconds_since_progress = 0;  // since a frame last left the flow element (or it began playing)
  double last_flow_unix_s = 0;        // wall-clock time of the last flow (to a second); 0: none yet
  struct Sink {
    std::string name;
    std::string kind;                 // pipeline::sink_kind()
    bool counts_flows = false;        // files and shm sinks count what they write
    std::uint64_t flows_written = 0;  // over all runs
    std::uint64_t bytes_written = 0;
    std::uint64_t failures = 0;
  };
  std::vector<Sink> sinks;  // in config order
};

// One sink's counts since the daemon started.
struct SinkTotals {
  std::uint64_t flows_written = 0;
  std::uint64_t bytes_written = 0;
  std::uint64_t failures = 0;
};

// What a stream has counted since the daemon started, carried from one Stream object to the
// next when a reload rebuilds it, so Prometheus sees its counters reset only at process start.
struct StreamTotals {
  std::uint64_t frames_in = 0;
  std::uint64_t frames_processed = 0;
  std::uint64_t frames_dropped = 0;
  std::uint64_t flows = 0;
  std::uint64_t restarts = 0;
  LatencyCounts inference;
  std::map<std::string, SinkTotals> sinks;  // by sink name
};

class Stream {
 public:
  using Clock = std::chrono::steady_clock;

  // `threads`: inference threads for this stream's flow element; `carried`: the totals of the
  // stream of the same name that this one replaces.
  Stream(StreamConfig config, int threads, DaemonSettings settings, StreamTotals carried = {});
  ~Stream();
  Stream(const Stream&) = delete;
  Stream& operator=(const Stream&) = delete;

  void start();
  // Ends the stream with EOS (bounded by stop-timeout), then calls `done` on the main loop.
  void stop(std::function<void()> done);
  // Once a second: reads the counters, restarts a stalled stream.
  void tick();
  // Reads the flow element's counters now (for a metrics scrape between ticks).
  void refresh_counters() { read_counters(); }

  const std::string& name() const { return config_.name; }
  const StreamConfig& config() const { return config_; }
  int threads() const { return threads_; }
  StreamState state() const { return state_; }
  // True once the first start has settled: playing, failed or finished (for READY=1).
  bool settled() const { return settled_; }
  // Whether the supervisor is in control (for WATCHDOG=1): false when a state change has
  // taken far longer than it may.
  bool healthy() const;
  StreamSnapshot snapshot() const;
  StreamTotals totals() const;
  std::string status() const;  // short, for STATUS=

 private:
  static gboolean on_bus_message(GstBus*, GstMessage* message, gpointer self);
  static GstBusSyncReply on_bus_sync(GstBus*, GstMessage* message, gpointer graph);
  static gboolean on_restart_timer(gpointer self);
  static gboolean on_stop_timeout(gpointer self);
  static GstPadProbeReturn on_flow_buffer(GstPad*, GstPadProbeInfo* info, gpointer self);
  void count_sink_failure(const std::string& sink);
  double seconds_until_restart() const;  // backoff

  void handle_message(GstMessage* message);
  void fail(const std::string& reason);
  void teardown();
  void finish_stop();
  void enter(StreamState state);
  void mark_playing();
  void read_counters();

  StreamConfig config_;
  int threads_;
  DaemonSettings settings_;
  std::unique_ptr<StreamGraph> graph_;
  guint bus_watch_ = 0;
  guint restart_timer_ = 0;
  guint stop_timer_ = 0;
  std::function<void()> stop_done_;

  StreamState state_ = StreamState::idle;
  Clock::time_point state_since_ = Clock::now();
  Clock::time_point restart_at_{};
  Clock::time_point last_progress_{};
  double backoff_s_ = 0;
  bool settled_ = false;
  int run_ = 0;  // pipeline instances started, for names in GStreamer's logs

  // Counters: `base_` holds what finished runs counted, `current_` the running pipeline's.
  struct Counters {
    std::uint64_t in = 0, processed = 0, dropped = 0, flows = 0;
  } base_, current_;
  double rate_fps_ = 0;
  std::uint64_t last_processed_ = 0;  // for stall detection
  std::uint64_t last_flows_ = 0;      // over all runs, when last_flow_at_ was taken
  std::chrono::system_clock::time_point last_flow_at_{};
  std::uint64_t rate_base_ = 0;  // processed count at the last rate measurement
  Clock::time_point last_rate_at_{};
  bool rate_known_ = false;  // a rate has been measured in this run
  // Per sink: what finished runs wrote (and failures), and what the running pipeline wrote.
  std::map<std::string, SinkTotals> sink_base_;
  std::map<std::string, SinkTotals> sink_written_now_;  // failures unused
  // Filled from the flow element's src pad (a streaming thread), read by scrapes.
  LatencyHistogram inference_;
  gulong inference_probe_ = 0;
  std::uint64_t restarts_ = 0;
};

}  // namespace neuflow::daemon
