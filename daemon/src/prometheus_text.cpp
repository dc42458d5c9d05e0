#include "prometheus_text.hpp"

#include <charconv>
#include <cmath>
#include <functional>

namespace neuflow::daemon {

std::string escape_label_value(std::string_view value) {
  std::string out;
  out.reserve(value.size());
  for (char c : value) {
    switch (c) {
      case '\\': out += "\\\\"; break;
      case '"': out += "\\\""; break;
      case '\n': out += "\\n"; break;
      default: out += c;
    }
  }
  return out;
}

std::string format_sample_value(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "+Inf" : "-Inf";
  // Shortest round-trip form: 3 rather than 3.000000, 0.1 rather than 0.10000000000000001.
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

namespace {

class Exposition {
 public:
  // Opens a family: its metadata lines, written once before all of its samples (the format
  // requires a family's samples to be contiguous).
  void family(const char* name, const char* type, const char* help) {
    name_ = name;
    text_ += "# HELP ";
    text_ += name;
    text_ += ' ';
    text_ += help;
    text_ += "\n# TYPE ";
    text_ += name;
    text_ += ' ';
    text_ += type;
    text_ += '\n';
  }

  void sample(std::string_view labels, const std::string& value) { sample(std::string_view(), labels, value); }
  void sample(std::string_view labels, std::uint64_t value) { sample(labels, std::to_string(value)); }
  void sample(std::string_view labels, double value) { sample(labels, format_sample_value(value)); }

  // A sample of the family under a suffixed name (a histogram's _bucket, _sum and _count).
  void sample(std::string_view suffix, std::string_view labels, std::uint64_t value) {
    sample(suffix, labels, std::to_string(value));
  }
  void sample(std::string_view suffix, std::string_view labels, double value) {
    sample(suffix, labels, format_sample_value(value));
  }
  void sample(std::string_view suffix, std::string_view labels, const std::string& value) {
    text_ += name_;
    text_ += suffix;
    if (!labels.empty()) {
      text_ += '{';
      text_ += labels;
      text_ += '}';
    }
    text_ += ' ';
    text_ += value;
    text_ += '\n';
  }

  std::string take() { return std::move(text_); }

 private:
  std::string text_;
  const char* name_ = "";
};

std::string stream_label(const StreamMetrics& s) { return "stream=\"" + escape_label_value(s.stream) + "\""; }

}  // namespace

std::string render_prometheus(const std::vector<StreamMetrics>& streams, double daemon_uptime_s,
                              std::string_view version) {
  Exposition out;
  out.family("neuflow_build_info", "gauge", "Always 1; the version of neuflowd in its label.");
  out.sample("version=\"" + escape_label_value(version) + "\"", std::uint64_t{1});
  out.family("neuflow_daemon_uptime_seconds", "gauge", "Seconds since neuflowd started.");
  out.sample("", daemon_uptime_s);
  if (streams.empty()) return out.take();

  const auto per_stream = [&](const char* name, const char* type, const char* help,
                              const std::function<void(const StreamMetrics&, const std::string&)>& emit) {
    out.family(name, type, help);
    for (const auto& s : streams) emit(s, stream_label(s));
  };

  per_stream("neuflow_stream_up", "gauge",
             "1 while the stream is playing and a frame left the flow element in the last 5 s, else 0.",
             [&](const StreamMetrics& s, const std::string& l) {
               out.sample(l, std::uint64_t{s.state == "playing" && !s.stalled ? 1u : 0u});
             });
  // Every known state gets a series (0 or 1) so that a state change never makes a series
  // vanish; a state this code does not know is still shown rather than lost.
  per_stream("neuflow_stream_state", "gauge", "The stream's state: 1 for the current one, 0 for the others.",
             [&](const StreamMetrics& s, const std::string& l) {
               bool known = false;
               for (const char* state : kStreamStates) {
                 const bool current = s.state == state;
                 known = known || current;
                 out.sample(l + ",state=\"" + state + "\"", std::uint64_t{current ? 1u : 0u});
               }
               if (!known) out.sample(l + ",state=\"" + escape_label_value(s.state) + "\"", std::uint64_t{1});
             });
  per_stream("neuflow_frames_in_total", "counter", "Frames that reached the flow element.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.frames_in); });
  per_stream("neuflow_frames_processed_total", "counter",
             "Frames that left the flow element, with or without a flow (the first frame of a stream has none).",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.frames_processed); });
  per_stream("neuflow_frames_dropped_total", "counter",
             "Frames dropped before inference because a newer frame had arrived (live mode).",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.frames_dropped); });
  per_stream("neuflow_flows_total", "counter", "Flow fields computed and passed on to the stream's sinks.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.flows); });
  per_stream("neuflow_stream_restarts_total", "counter", "Restarts of the stream after a failure or a stall.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.restarts); });
  per_stream("neuflow_inference_seconds", "histogram", "Inference time of each flow, in seconds.",
             [&](const StreamMetrics& s, const std::string& l) {
               std::uint64_t cumulative = 0;
               for (std::size_t i = 0; i < LatencyCounts::kBounds.size(); ++i) {
                 cumulative += s.inference.buckets[i];
                 out.sample("_bucket", l + ",le=\"" + format_sample_value(LatencyCounts::kBounds[i]) + "\"",
                            cumulative);
               }
               out.sample("_bucket", l + ",le=\"+Inf\"", s.inference.count);
               out.sample("_sum", l, s.inference.sum);
               out.sample("_count", l, s.inference.count);
             });
  per_stream("neuflow_stream_uptime_seconds", "gauge",
             "Seconds since the stream last started playing; 0 while it is not playing.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.uptime_s); });
  per_stream("neuflow_last_flow_timestamp_seconds", "gauge",
             "Unix time of the stream's last flow, to a second; 0 before its first.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.last_flow_unix_s); });
  const auto per_sink = [&](const char* name, const char* help, bool counted_only,
                            const std::function<std::uint64_t(const SinkMetrics&)>& value) {
    bool any = false;
    for (const auto& s : streams) {
      for (const auto& sink : s.sinks) {
        if (counted_only && !sink.counts_flows) continue;
        if (!any) out.family(name, "counter", help);
        any = true;
        out.sample(stream_label(s) + ",sink=\"" + escape_label_value(sink.sink) + "\",kind=\"" +
                       escape_label_value(sink.kind) + "\"",
                   value(sink));
      }
    }
  };
  per_sink("neuflow_sink_flows_written_total", "Flows the sink wrote (flow files, or flows published into the ring).",
           true, [](const SinkMetrics& sink) { return sink.flows_written; });
  per_sink("neuflow_sink_bytes_written_total",
           "Bytes the sink wrote: the flow files' sizes, or the vectors published into the ring.", true,
           [](const SinkMetrics& sink) { return sink.bytes_written; });
  per_sink("neuflow_sink_failures_total", "Times the sink failed or could not be built and was cut off.", false,
           [](const SinkMetrics& sink) { return sink.failures; });
  return out.take();
}

}  // namespace neuflow::daemon
