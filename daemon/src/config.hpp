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

namespace neuflow::daemon {

struct SourcePosition {
  int line = 0;    // 1-based; 0 when not known
  int column = 0;  // 1-based
  friend bool operator==(const SourcePosition&, const SourcePosition&) { return true; }
};

// ---- sources -------------------------------------------------------------------------------

// Optional caps for camera and test sources; 0 leaves the choice to negotiation.
struct VideoMode {
  int width = 0;
  int height = 0;
  int framerate_num = 0;  // `framerate = 30` or `framerate = "30000/1001"`
  int framerate_den = 1;
  bool operator==(const VideoMode&) const = default;
};

struct V4l2Source {       // type = "v4l2"
  std::string device = "/dev/video0";
  VideoMode mode;
  bool mjpeg = false;     // `format = "mjpeg"`: ask the camera for JPEG and decode it
  bool operator==(const V4l2Source&) const = default;
};

struct LibcameraSource {  // type = "libcamera"
  std::string camera;     // libcamerasrc camera-name; empty: the first camera
  VideoMode mode;
  bool operator==(const LibcameraSource&) const = default;
};

struct UriSource {        // type = "uri"
  std::string uri;        // file://, rtsp://, http(s)://; a plain path in the file is made a file:// URI
  bool operator==(const UriSource&) const = default;
};

struct TestSource {       // type = "test"
  std::string pattern = "ball";  // a videotestsrc pattern nick
  VideoMode mode;                // defaults applied by the graph: 320x240 at 30/1
  int frames = -1;               // `frames = N`: end of stream after N frames; -1: endless
  bool live = true;              // paced like a camera
  bool operator==(const TestSource&) const = default;
};

using SourceSettings = std::variant<V4l2Source, LibcameraSource, UriSource, TestSource>;

struct SourceConfig {
  SourceSettings settings;
  SourcePosition where;
  bool operator==(const SourceConfig&) const = default;
};

// ---- flow ----------------------------------------------------------------------------------

// The neuflow element's properties, under the same names in the file.
struct FlowConfig {
  std::filesystem::path model;   // model = "/var/lib/neuflow/neuflow_mixed.pth" (required)
  int iters_s16 = model::Iterations{}.s16;  // iters-s16
  int iters_s8 = model::Iterations{}.s8;    // iters-s8
  int model_width = 0;           // model-width / model-height: 0 = the frames' own size
  int model_height = 0;
  int threads = 0;               // 0: an equal share of [daemon] threads
  std::string behaviour = "auto";      // auto | live | every-pair
  std::string channel_order = "rgb";   // rgb | bgr
  SourcePosition where;
  bool operator==(const FlowConfig&) const = default;
};

// ---- sinks ---------------------------------------------------------------------------------

struct FilesSink {        // type = "files"
  std::filesystem::path directory;    // required; created if missing
  std::string format = "flo";         // flo | npy | png
  std::uint64_t max_files = 0;        // max-files: oldest removed first; 0 = no limit
  std::uint64_t max_bytes = 0;        // max-bytes: same, by total size; 0 = no limit
  bool operator==(const FilesSink&) const = default;
};

struct ShmSink {          // type = "shm"
  std::string name;       // POSIX shm name, e.g. "/neuflow-front" (required, leading '/')
  int slots = 4;          // the latest N flows
  unsigned mode = 0640;   // shm-mode = "0640" (or 0o640): the segment's permissions
  bool operator==(const ShmSink&) const = default;
};

// The encoded (H.264) colour visualization. Exactly one of `file`, `rtsp`, `udp` is given.
struct VideoSink {        // type = "video"
  enum class Target { file, rtsp, udp };
  Target target = Target::file;
  std::filesystem::path file;         // file = ".../viz-%05d.mp4" (.mp4 or .mkv)
  int segment_seconds = 0;            // segment-seconds: a new file every N s; 0 = one file
  std::string rtsp_mount;             // rtsp = "/front": a mount on the [rtsp] server
  std::string udp_host;               // udp = "192.168.1.10:5000": RTP/H.264 over UDP
  int udp_port = 0;
  int bitrate_kbps = 2000;            // bitrate (kbit/s)
  double max_flow = 20.0;             // max-flow: px of full colour saturation
  bool operator==(const VideoSink&) const = default;
};

struct DisplaySink {      // type = "display": a window, for debugging
  double max_flow = 20.0;
  bool operator==(const DisplaySink&) const = default;
};

using SinkSettings = std::variant<FilesSink, ShmSink, VideoSink, DisplaySink>;

struct SinkConfig {
  std::string name;       // `name = "..."`, default "<type>-<index>"; used in logs and metrics
  SinkSettings settings;
  SourcePosition where;
  bool operator==(const SinkConfig&) const = default;
};

// ---- streams and the whole file ------------------------------------------------------------

struct StreamConfig {
  std::string name;       // [[stream]] name = "front": unique, [A-Za-z0-9_-]+
  SourceConfig source;
  FlowConfig flow;
  std::vector<SinkConfig> sinks;  // at least one
  SourcePosition where;
  bool operator==(const StreamConfig&) const = default;
};

struct DaemonSettings {   // [daemon]
  std::string log_level = "info";     // log-level: error | warning | notice | info | debug
  int threads = 0;                    // inference threads shared by all streams; 0 = all cores
  double restart_delay_min = 1.0;     // restart-delay-min (s): first backoff after a failure
  double restart_delay_max = 60.0;    // restart-delay-max (s): backoff cap
  double stop_timeout = 10.0;         // stop-timeout (s): wait for EOS to finish files on stop
  double stall_timeout = 30.0;        // stall-timeout (s): a playing stream with no frames is restarted
  bool operator==(const DaemonSettings&) const = default;
};

struct MetricsSettings {  // [metrics]; absent: no endpoint
  std::string address = "127.0.0.1";  // listen = "127.0.0.1:9464"
  int port = 9464;
  bool operator==(const MetricsSettings&) const = default;
};

struct RtspSettings {     // [rtsp]; needed when a video sink uses `rtsp`
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
  std::string message;    // what is wrong and what was expected
  Severity severity = Severity::error;
  bool is_warning() const { return severity == Severity::warning; }
  std::string to_string() const;  // "FILE:LINE:COLUMN: message", "FILE:LINE:COLUMN: warning: message"
};

struct Config {
  std::filesystem::path file;         // where it was read from
  DaemonSettings daemon;
  std::optional<MetricsSettings> metrics;
  std::optional<RtspSettings> rtsp;
  std::vector<StreamConfig> streams;  // at least one
  // What the machine lacks now (ConfigChecks::all): logged, never fatal.
  std::vector<ConfigIssue> warnings;
};

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
