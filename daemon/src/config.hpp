#pragma once
// neuflowd's configuration: what one TOML file describes (global settings and one or more
// streams, each a source, flow settings and one or more sinks), and the loader that checks it.
//
// Every setting remembers where it was written (line, column) so that errors found later, at
// start or at run time, can point at it. Positions never make two settings differ: a reload
// restarts a stream only when what it does changed, not when its lines moved.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <variant>
#include <vector>

#include "neuflow/model/session_settings.hpp"
#include "neuflow/pipeline/graph_description.hpp"

namespace neuflow::daemon {

struct SourcePosition {
  int line = 0;    // 1-based; 0 when not known
  int column = 0;  // 1-based
  friend bool operator==(const SourcePosition&, const SourcePosition&) { return true; }
};

// ---- sources -------------------------------------------------------------------------------

using pipeline::LibcameraSource;
using pipeline::TestSource;
using pipeline::UriSource;
using pipeline::V4l2Source;
using pipeline::VideoMode;

using SourceSettings = pipeline::SourceDescription;

struct SourceConfig {
  SourceSettings settings;
  SourcePosition where;
  bool operator==(const SourceConfig&) const = default;
};

// ---- flow ----------------------------------------------------------------------------------

// The neuflow element's properties, under the same names in the file, read straight into the
// graph's typed flow stage: model, iters-s16, iters-s8, model-width, model-height, threads,
// behaviour, channel-order, backend, device, precision. stage.session.threads = 0 means an
// equal share of [daemon] threads, resolved per stream when the graph is made.
struct FlowConfig {
  pipeline::FlowStage stage;
  SourcePosition where;
  bool operator==(const FlowConfig&) const = default;
};

// ---- sinks ---------------------------------------------------------------------------------

using pipeline::DisplaySink;
using pipeline::FilesSink;
using pipeline::ShmSink;
using pipeline::VideoSink;

using SinkSettings = pipeline::SinkDescription;

struct SinkConfig {
  std::string name;  // `name = "..."`, default "<type>-<index>"; used in logs and metrics
  SinkSettings settings;
  SourcePosition where;
  bool operator==(const SinkConfig&) const = default;
};

// ---- streams and the whole file ------------------------------------------------------------

struct StreamConfig {
  std::string name;  // [[stream]] name = "front": unique, [A-Za-z0-9_-]+
  SourceConfig source;
  FlowConfig flow;
  std::vector<SinkConfig> sinks;  // at least one
  SourcePosition where;
  bool operator==(const StreamConfig&) const = default;
};

struct DaemonSettings {             // [daemon]
  std::string log_level = "info";   // log-level: error | warning | notice | info | debug
  int threads = 0;                  // inference threads shared by all streams; 0 = all cores
  double restart_delay_min = 1.0;   // restart-delay-min (s): first backoff after a failure
  double restart_delay_max = 60.0;  // restart-delay-max (s): backoff cap
  double stop_timeout = 10.0;       // stop-timeout (s): wait for EOS to finish files on stop
  double stall_timeout = 30.0;      // stall-timeout (s): a playing stream with no frames is restarted
  bool operator==(const DaemonSettings&) const = default;
};

struct MetricsSettings {              // [metrics]; absent: no endpoint
  std::string address = "127.0.0.1";  // listen = "127.0.0.1:9464"
  int port = 9464;
  bool operator==(const MetricsSettings&) const = default;
};

struct RtspSettings {                 // [rtsp]; needed when a video sink uses `rtsp`
  std::string address = "127.0.0.1";  // listen = "127.0.0.1:8554"; "0.0.0.0:8554" for the network
  int port = 8554;
  std::filesystem::path credentials;  // credentials = "/etc/neuflow/rtsp-users": user:password lines
  std::string auth = "digest";        // auth = "digest" | "basic" (with credentials)
  bool operator==(const RtspSettings&) const = default;
};

struct ConfigIssue {
  // An error makes the file unusable; a warning is about this machine as it is now (a camera
  // not plugged in yet, a model not fetched yet): the stream waits for it, in backoff.
  enum class Severity { error, warning };
  std::filesystem::path file;
  int line = 0;
  int column = 0;
  std::string message;  // what is wrong and what was expected
  Severity severity = Severity::error;
  bool is_warning() const { return severity == Severity::warning; }
  std::string to_string() const;  // "FILE:LINE:COLUMN: message", "FILE:LINE:COLUMN: warning: message"
  // "FILE:LINE:COLUMN: message" whatever the severity, for a log line that states it already.
  std::string where_and_what() const;
  // The line of the file it is about, indented, and a caret under the column; empty when the
  // issue has no line or the file cannot be read.
  std::string source_excerpt() const;
};

struct Config {
  std::filesystem::path file;  // where it was read from
  DaemonSettings daemon;
  std::optional<MetricsSettings> metrics;
  std::optional<RtspSettings> rtsp;
  std::vector<StreamConfig> streams;  // at least one
  // What the machine lacks now (ConfigChecks::all): logged, never fatal.
  std::vector<ConfigIssue> warnings;
};

// The stream as the graph library builds it; its flow element gets `threads` (the stream's share).
pipeline::GraphDescription graph_description(const StreamConfig& stream, int threads);

// ---- loading -------------------------------------------------------------------------------

// Thrown by load_config with every issue found (not just the first): at least one error, and
// the machine's warnings beside them.
class ConfigError : public std::runtime_error {
 public:
  explicit ConfigError(std::vector<ConfigIssue> issues);
  const std::vector<ConfigIssue>& issues() const { return issues_; }

 private:
  std::vector<ConfigIssue> issues_;
};

// How far the loader looks.
enum class ConfigChecks {
  // The file alone: TOML syntax, unknown keys, types and ranges, required keys, names and
  // references between streams. Needs nothing from the machine (the shipped examples are
  // tested this way on machines without their cameras and models).
  file_only,
  // Also what the file refers to on this machine: the model file, v4l2 device nodes, input
  // files, that output directories exist or can be created, that the GStreamer elements a
  // stream needs are installed. These are warnings (Config::warnings), never errors: a camera
  // that enumerates late or a model fetched after the daemon started must not keep it down.
  // The caller must have called gst_init() (std::logic_error if not).
  all,
};

// Reads and checks a config file (see ConfigChecks). Relative paths in it are resolved against
// the file's folder; the Config holds absolute paths. Throws ConfigError with every issue found
// when there is at least one error. Bytes that are not UTF-8 text, control characters and
// non-ASCII characters outside strings and comments are errors before TOML parsing starts.
Config load_config(const std::filesystem::path& file, ConfigChecks checks = ConfigChecks::all);

// The same from a string (tests); `file` only names it in messages, and relative paths in
// the config are resolved against its folder.
Config parse_config(const std::string& text, const std::filesystem::path& file,
                    ConfigChecks checks = ConfigChecks::all);

}  // namespace neuflow::daemon
