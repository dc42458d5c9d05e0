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

  void sample(std::string_view labels, const std::string& value) {
    text_ += name_;
    if (!labels.empty()) {
      text_ += '{';
      text_ += labels;
      text_ += '}';
    }
    text_ += ' ';
    text_ += value;
    text_ += '\n';
  }
  void sample(std::string_view labels, std::uint64_t value) { sample(labels, std::to_string(value)); }
  void sample(std::string_view labels, double value) { sample(labels, format_sample_value(value)); }

  std::string take() { return std::move(text_); }

 private:
  std::string text_;
  const char* name_ = "";
};

std::string stream_label(const StreamMetrics& s) {
  return "stream=\"" + escape_label_value(s.stream) + "\"";
}

}  // namespace

std::string render_prometheus(const std::vector<StreamMetrics>& streams, double daemon_uptime_s) {
  Exposition out;
  out.family("neuflow_daemon_uptime_seconds", "gauge", "Seconds since neuflowd started.");
  out.sample("", daemon_uptime_s);
  if (streams.empty()) return out.take();

  const auto per_stream = [&](const char* name, const char* type, const char* help,
                              const std::function<void(const StreamMetrics&, const std::string&)>& emit) {
    out.family(name, type, help);
    for (const auto& s : streams) emit(s, stream_label(s));
  };

  per_stream("neuflow_stream_up", "gauge", "1 while the stream is playing, else 0.",
             [&](const StreamMetrics& s, const std::string& l) {
               out.sample(l, std::uint64_t{s.state == "playing" ? 1u : 0u});
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
  per_stream("neuflow_frames_processed_total", "counter", "Frames the network computed a flow for.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.frames_processed); });
  per_stream("neuflow_frames_dropped_total", "counter",
             "Frames dropped before inference because a newer frame had arrived (live mode).",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.frames_dropped); });
  per_stream("neuflow_flows_total", "counter", "Flow fields delivered to the stream's sinks.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.flows); });
  per_stream("neuflow_stream_restarts_total", "counter", "Restarts of the stream after a failure or a stall.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.restarts); });
  per_stream("neuflow_sink_failures_total", "counter", "Sinks of the stream that failed and were cut off.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.sink_failures); });
  per_stream("neuflow_inference_latency_seconds", "gauge",
             "Mean inference time of the stream's recent flows (NaN before the first).",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.latency_ms_mean / 1000.0); });
  per_stream("neuflow_processing_fps", "gauge", "Flows computed per second, recently.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.processing_fps); });
  per_stream("neuflow_stream_uptime_seconds", "gauge",
             "Seconds since the stream last started playing; 0 while it is not playing.",
             [&](const StreamMetrics& s, const std::string& l) { out.sample(l, s.uptime_s); });
  return out.take();
}

}  // namespace neuflow::daemon
