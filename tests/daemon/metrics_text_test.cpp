// render_prometheus: the exact exposition for a known snapshot, label escaping, number
// formatting, and a check of the output against the text format's grammar (what a Prometheus
// server's parser requires: metadata once per family before its samples, contiguous families,
// well-formed samples and label values that read back to the originals).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "prometheus_text.hpp"

namespace neuflow::daemon {
namespace {

std::vector<StreamMetrics> known_snapshot() {
  StreamMetrics front;
  front.stream = "front";
  front.state = "playing";
  front.frames_in = 1200;
  front.frames_processed = 1150;
  front.frames_dropped = 50;
  front.flows = 1149;
  front.restarts = 1;
  for (const double seconds : {0.125, 0.25, 0.5}) front.inference.add(seconds);  // 0.25 is on a bound: le="0.25"
  front.uptime_s = 81.5;
  front.last_flow_unix_s = 1765012345.5;
  front.sinks = {{"archive", "files", true, 1149, 4711, 0}, {"live", "rtsp", false, 0, 0, 1}};

  StreamMetrics odd;
  odd.stream = "odd \"name\"\\ with\nnewline";
  odd.state = "backoff";
  odd.restarts = 3;
  return {front, odd};
}

TEST(PrometheusText, RendersKnownSnapshotExactly) {
  const std::string expected = R"(# HELP neuflow_build_info Always 1; the version of neuflowd in its label.
# TYPE neuflow_build_info gauge
neuflow_build_info{version="1.2.3"} 1
# HELP neuflow_daemon_uptime_seconds Seconds since neuflowd started.
# TYPE neuflow_daemon_uptime_seconds gauge
neuflow_daemon_uptime_seconds 120.25
# HELP neuflow_stream_up 1 while the stream is playing and a frame left the flow element in the last 5 s, else 0.
# TYPE neuflow_stream_up gauge
neuflow_stream_up{stream="front"} 1
neuflow_stream_up{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_stream_state The stream's state: 1 for the current one, 0 for the others.
# TYPE neuflow_stream_state gauge
neuflow_stream_state{stream="front",state="playing"} 1
neuflow_stream_state{stream="front",state="starting"} 0
neuflow_stream_state{stream="front",state="backoff"} 0
neuflow_stream_state{stream="front",state="stopped"} 0
neuflow_stream_state{stream="front",state="finished"} 0
neuflow_stream_state{stream="odd \"name\"\\ with\nnewline",state="playing"} 0
neuflow_stream_state{stream="odd \"name\"\\ with\nnewline",state="starting"} 0
neuflow_stream_state{stream="odd \"name\"\\ with\nnewline",state="backoff"} 1
neuflow_stream_state{stream="odd \"name\"\\ with\nnewline",state="stopped"} 0
neuflow_stream_state{stream="odd \"name\"\\ with\nnewline",state="finished"} 0
# HELP neuflow_frames_in_total Frames that reached the flow element.
# TYPE neuflow_frames_in_total counter
neuflow_frames_in_total{stream="front"} 1200
neuflow_frames_in_total{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_frames_processed_total Frames that left the flow element, with or without a flow (the first frame of a stream has none).
# TYPE neuflow_frames_processed_total counter
neuflow_frames_processed_total{stream="front"} 1150
neuflow_frames_processed_total{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_frames_dropped_total Frames dropped before inference because a newer frame had arrived (live mode).
# TYPE neuflow_frames_dropped_total counter
neuflow_frames_dropped_total{stream="front"} 50
neuflow_frames_dropped_total{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_flows_total Flow fields computed and passed on to the stream's sinks.
# TYPE neuflow_flows_total counter
neuflow_flows_total{stream="front"} 1149
neuflow_flows_total{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_stream_restarts_total Restarts of the stream after a failure or a stall.
# TYPE neuflow_stream_restarts_total counter
neuflow_stream_restarts_total{stream="front"} 1
neuflow_stream_restarts_total{stream="odd \"name\"\\ with\nnewline"} 3
# HELP neuflow_inference_seconds Inference time of each flow, in seconds.
# TYPE neuflow_inference_seconds histogram
neuflow_inference_seconds_bucket{stream="front",le="0.01"} 0
neuflow_inference_seconds_bucket{stream="front",le="0.025"} 0
neuflow_inference_seconds_bucket{stream="front",le="0.05"} 0
neuflow_inference_seconds_bucket{stream="front",le="0.1"} 0
neuflow_inference_seconds_bucket{stream="front",le="0.25"} 2
neuflow_inference_seconds_bucket{stream="front",le="0.5"} 3
neuflow_inference_seconds_bucket{stream="front",le="1"} 3
neuflow_inference_seconds_bucket{stream="front",le="2.5"} 3
neuflow_inference_seconds_bucket{stream="front",le="5"} 3
neuflow_inference_seconds_bucket{stream="front",le="10"} 3
neuflow_inference_seconds_bucket{stream="front",le="30"} 3
neuflow_inference_seconds_bucket{stream="front",le="60"} 3
neuflow_inference_seconds_bucket{stream="front",le="+Inf"} 3
neuflow_inference_seconds_sum{stream="front"} 0.875
neuflow_inference_seconds_count{stream="front"} 3
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.01"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.025"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.05"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.1"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.25"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="0.5"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="1"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="2.5"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="5"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="10"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="30"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="60"} 0
neuflow_inference_seconds_bucket{stream="odd \"name\"\\ with\nnewline",le="+Inf"} 0
neuflow_inference_seconds_sum{stream="odd \"name\"\\ with\nnewline"} 0
neuflow_inference_seconds_count{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_stream_uptime_seconds Seconds since the stream last started playing; 0 while it is not playing.
# TYPE neuflow_stream_uptime_seconds gauge
neuflow_stream_uptime_seconds{stream="front"} 81.5
neuflow_stream_uptime_seconds{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_last_flow_timestamp_seconds Unix time of the stream's last flow, to a second; 0 before its first.
# TYPE neuflow_last_flow_timestamp_seconds gauge
neuflow_last_flow_timestamp_seconds{stream="front"} 1765012345.5
neuflow_last_flow_timestamp_seconds{stream="odd \"name\"\\ with\nnewline"} 0
# HELP neuflow_sink_flows_written_total Flows the sink wrote (flow files, or flows published into the ring).
# TYPE neuflow_sink_flows_written_total counter
neuflow_sink_flows_written_total{stream="front",sink="archive",kind="files"} 1149
# HELP neuflow_sink_bytes_written_total Bytes the sink wrote: the flow files' sizes, or the vectors published into the ring.
# TYPE neuflow_sink_bytes_written_total counter
neuflow_sink_bytes_written_total{stream="front",sink="archive",kind="files"} 4711
# HELP neuflow_sink_failures_total Times the sink failed or could not be built and was cut off.
# TYPE neuflow_sink_failures_total counter
neuflow_sink_failures_total{stream="front",sink="archive",kind="files"} 0
neuflow_sink_failures_total{stream="front",sink="live",kind="rtsp"} 1
)";
  EXPECT_EQ(render_prometheus(known_snapshot(), 120.25, "1.2.3"), expected);
}

TEST(PrometheusText, WithoutStreamsOnlyTheDaemonIsReported) {
  EXPECT_EQ(render_prometheus({}, 0.5, "1.2.3"),
            "# HELP neuflow_build_info Always 1; the version of neuflowd in its label.\n"
            "# TYPE neuflow_build_info gauge\n"
            "neuflow_build_info{version=\"1.2.3\"} 1\n"
            "# HELP neuflow_daemon_uptime_seconds Seconds since neuflowd started.\n"
            "# TYPE neuflow_daemon_uptime_seconds gauge\n"
            "neuflow_daemon_uptime_seconds 0.5\n");
}

TEST(PrometheusText, EscapesLabelValues) {
  EXPECT_EQ(escape_label_value("front"), "front");
  EXPECT_EQ(escape_label_value(""), "");
  EXPECT_EQ(escape_label_value("a\\b"), "a\\\\b");
  EXPECT_EQ(escape_label_value("say \"hi\""), "say \\\"hi\\\"");
  EXPECT_EQ(escape_label_value("two\nlines"), "two\\nlines");
  EXPECT_EQ(escape_label_value("\\n"), "\\\\n");                            // a literal backslash-n is not a newline
  EXPECT_EQ(escape_label_value("tab\tand \xc3\xa9"), "tab\tand \xc3\xa9");  // kept as is
}

TEST(PrometheusText, FormatsSampleValues) {
  EXPECT_EQ(format_sample_value(0.0), "0");
  EXPECT_EQ(format_sample_value(3.0), "3");
  EXPECT_EQ(format_sample_value(-2.5), "-2.5");
  EXPECT_EQ(format_sample_value(0.1), "0.1");
  EXPECT_EQ(format_sample_value(1e21), "1e+21");
  EXPECT_EQ(format_sample_value(std::numeric_limits<double>::quiet_NaN()), "NaN");
  EXPECT_EQ(format_sample_value(std::numeric_limits<double>::infinity()), "+Inf");
  EXPECT_EQ(format_sample_value(-std::numeric_limits<double>::infinity()), "-Inf");
}

// A stream stuck behind a blocked sink still says "playing" until the stall timeout restarts
// it; it is not up.
TEST(PrometheusText, APlayingStreamWithoutFramesIsNotUp) {
  StreamMetrics s;
  s.stream = "cam";
  s.state = "playing";
  EXPECT_NE(render_prometheus({s}, 1.0, "1.2.3").find("neuflow_stream_up{stream=\"cam\"} 1\n"), std::string::npos);
  s.stalled = true;
  const std::string text = render_prometheus({s}, 1.0, "1.2.3");
  EXPECT_NE(text.find("neuflow_stream_up{stream=\"cam\"} 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("neuflow_stream_state{stream=\"cam\",state=\"playing\"} 1\n"), std::string::npos) << text;
}

TEST(PrometheusText, UnknownStateIsStillReported) {
  StreamMetrics s;
  s.stream = "cam";
  s.state = "paused";
  const std::string text = render_prometheus({s}, 1.0, "1.2.3");
  EXPECT_NE(text.find("neuflow_stream_state{stream=\"cam\",state=\"paused\"} 1\n"), std::string::npos) << text;
  EXPECT_NE(text.find("neuflow_stream_state{stream=\"cam\",state=\"playing\"} 0\n"), std::string::npos) << text;
  EXPECT_NE(text.find("neuflow_stream_up{stream=\"cam\"} 0\n"), std::string::npos) << text;
}

// ---- the text format's grammar ---------------------------------------------------------------

// Undoes escape_label_value's escapes as a Prometheus parser does; fails on anything else.
bool unescape(const std::string& escaped, std::string& out) {
  out.clear();
  for (size_t i = 0; i < escaped.size(); ++i) {
    if (escaped[i] != '\\') {
      out += escaped[i];
      continue;
    }
    if (++i == escaped.size()) return false;
    switch (escaped[i]) {
      case '\\': out += '\\'; break;
      case '"': out += '"'; break;
      case 'n': out += '\n'; break;
      default: return false;
    }
  }
  return true;
}

struct Parsed {
  std::map<std::string, std::string> types;                // family → counter/gauge
  std::vector<std::map<std::string, std::string>> labels;  // per sample, unescaped
  std::vector<std::string> errors;
};

Parsed parse_exposition(const std::string& text) {
  static const std::regex help(R"(# HELP ([a-zA-Z_:][a-zA-Z0-9_:]*) (.*))");
  static const std::regex type(R"(# TYPE ([a-zA-Z_:][a-zA-Z0-9_:]*) (counter|gauge|histogram|summary|untyped))");
  static const std::regex sample(
      R"(([a-zA-Z_:][a-zA-Z0-9_:]*)(\{(.*)\})? (NaN|[+-]Inf|[+-]?[0-9]+(\.[0-9]+)?([eE][+-]?[0-9]+)?))");
  static const std::regex label(R"(([a-zA-Z_][a-zA-Z0-9_]*)="((?:[^"\\]|\\.)*)\"(,|$))");
  Parsed p;
  std::string current;  // family being read
  bool help_seen = false;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  if (text.empty() || text.back() != '\n') p.errors.push_back("the exposition must end with a line feed");
  while (std::getline(lines, line)) {
    ++number;
    const std::string at = "line " + std::to_string(number) + ": ";
    std::smatch m;
    if (std::regex_match(line, m, help)) {
      current = m[1];
      if (p.types.count(current)) p.errors.push_back(at + "family " + current + " repeated");
      help_seen = true;
    } else if (std::regex_match(line, m, type)) {
      if (!help_seen || m[1] != current) p.errors.push_back(at + "# TYPE without its # HELP");
      if (p.types.count(m[1])) p.errors.push_back(at + "second # TYPE for " + m[1].str());
      p.types[m[1]] = m[2];
      help_seen = false;
    } else if (std::regex_match(line, m, sample)) {
      const std::string name = m[1];
      const bool histogram_part =
          p.types.count(current) && p.types[current] == "histogram" &&
          (name == current + "_bucket" || name == current + "_sum" || name == current + "_count");
      if ((name != current && !histogram_part) || !p.types.count(current))
        p.errors.push_back(at + "sample of " + name + " outside its family");
      if (p.types.count(current) && p.types[current] == "histogram" && !histogram_part)
        p.errors.push_back(at + "histogram sample " + name + " is not a _bucket, _sum or _count");
      if (p.types[current] == "counter" && !current.ends_with("_total"))
        p.errors.push_back(at + "counter not named *_total");
      std::map<std::string, std::string> labels;
      std::string rest = m[3];
      std::smatch l;
      while (!rest.empty()) {
        if (!std::regex_search(rest, l, label, std::regex_constants::match_continuous)) {
          p.errors.push_back(at + "malformed labels: " + rest);
          break;
        }
        std::string value;
        if (!unescape(l[2], value)) p.errors.push_back(at + "bad escape in " + l[2].str());
        if (!labels.emplace(l[1], value).second) p.errors.push_back(at + "label repeated: " + l[1].str());
        rest = l.suffix();
      }
      p.labels.push_back(labels);
    } else {
      p.errors.push_back(at + "not a metadata or sample line: " + line);
    }
  }
  return p;
}

// The checker itself must be able to fail, or the test above proves nothing.
TEST(PrometheusText, GrammarCheckRejectsBrokenExpositions) {
  const char* broken[] = {
      "x 1",                                                                      // no final line feed
      "x 1\n",                                                                    // sample without metadata
      "# HELP x h\n# TYPE x gauge\nx{a=\"1\"\",b=\"2\"} 1\n",                     // stray quote
      "# HELP x h\n# TYPE x gauge\nx{a=\"\\q\"} 1\n",                             // unknown escape
      "# HELP x h\n# TYPE x gauge\nx 1\n# HELP y h\n# TYPE y gauge\ny 1\nx 2\n",  // split family
      "# HELP x h\n# TYPE x gauge\nx 1\n# HELP x h\n# TYPE x gauge\n",            // repeated family
      "# HELP x h\n# TYPE x counter\nx 1\n",                                      // counter without _total
      "# HELP x h\n# TYPE x gauge\nx one\n",                                      // not a number
      "# HELP x h\n# TYPE x histogram\nx_total 1\n",                              // not a histogram's sample
  };
  for (const char* text : broken) EXPECT_FALSE(parse_exposition(text).errors.empty()) << text;
  EXPECT_TRUE(parse_exposition("# HELP x h\n# TYPE x gauge\nx{a=\"\\\"\\n\"} -1.5e3\n").errors.empty());
}

TEST(PrometheusText, OutputFollowsTheTextFormatGrammar) {
  auto snapshot = known_snapshot();
  StreamMetrics third;
  third.stream = "back\\\\slash\"\n\n";
  third.state = "finished";
  third.inference.add(std::numeric_limits<double>::infinity());  // not counted
  third.inference.add(1e9);                                      // counted under +Inf
  third.frames_in = std::numeric_limits<std::uint64_t>::max();
  third.sinks = {{"odd \"sink\"", "shm", true, 7, 672, 2}};
  snapshot.push_back(third);

  const Parsed p = parse_exposition(render_prometheus(snapshot, 3600.0, "0.1.0-dev \"x\""));
  for (const auto& e : p.errors) ADD_FAILURE() << e;

  EXPECT_EQ(p.types.size(), 15u);
  EXPECT_EQ(p.types.at("neuflow_inference_seconds"), "histogram");
  std::set<std::string> streams;
  for (const auto& labels : p.labels) {
    if (labels.count("stream")) streams.insert(labels.at("stream"));
  }
  // Every stream name reads back exactly as given, however odd.
  EXPECT_EQ(streams, (std::set<std::string>{snapshot[0].stream, snapshot[1].stream, snapshot[2].stream}));
}

}  // namespace
}  // namespace neuflow::daemon
