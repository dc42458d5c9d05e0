#pragma once
// What a capture → flow → sink graph is, as typed values: one source (a V4L2 or libcamera
// camera, a file or network URI, a test pattern), the flow stage (the neuflow element's
// settings) and one or more named sinks (flow files, a shared-memory ring, encoded
// visualization to a file, RTSP or RTP/UDP, a window). graph_plan.hpp turns a description into
// the GStreamer elements it needs; stream_graph.hpp builds and runs them. neuflowd's config
// file is read into these types.
#include <cstdint>
#include <filesystem>
#include <string>
#include <variant>
#include <vector>

#include "neuflow/model/session_settings.hpp"

namespace neuflow::pipeline {

// ---- sources -------------------------------------------------------------------------------

// Optional caps for camera and test sources; 0 leaves the choice to negotiation.
struct VideoMode {
  int width = 0;
  int height = 0;
  int framerate_num = 0;  // `framerate = 30` or `framerate = "30000/1001"`
  int framerate_den = 1;
  bool operator==(const VideoMode&) const = default;
};

struct V4l2Source {  // type = "v4l2"
  std::string device = "/dev/video0";
  VideoMode mode;
  bool mjpeg = false;  // `format = "mjpeg"`: ask the camera for JPEG and decode it
  bool operator==(const V4l2Source&) const = default;
};

struct LibcameraSource {  // type = "libcamera"
  std::string camera;     // libcamerasrc camera-name; empty: the first camera
  VideoMode mode;
  bool operator==(const LibcameraSource&) const = default;
};

struct UriSource {  // type = "uri"
  std::string uri;  // file://, rtsp://, http(s)://; a plain path in the file is made a file:// URI
  bool operator==(const UriSource&) const = default;
};

struct TestSource {              // type = "test"
  std::string pattern = "ball";  // a videotestsrc pattern nick
  VideoMode mode;                // defaults applied by the graph: 320x240 at 30/1
  int frames = -1;               // `frames = N`: end of stream after N frames; -1: endless
  bool live = true;              // paced like a camera
  bool operator==(const TestSource&) const = default;
};

using SourceDescription = std::variant<V4l2Source, LibcameraSource, UriSource, TestSource>;

// ---- the flow stage ------------------------------------------------------------------------

struct FlowStage {
  std::filesystem::path model;    // a NeuFlow-V2 checkpoint (.pth)
  model::SessionOptions session;  // iterations, model size, channel order; threads as given
  model::Behaviour behaviour = model::Behaviour::automatic;
  bool operator==(const FlowStage&) const = default;
};

// ---- sinks ---------------------------------------------------------------------------------

struct FilesSink {                  // type = "files"
  std::filesystem::path directory;  // required; created if missing
  std::string format = "flo";       // flo | npy | png
  std::uint64_t max_files = 0;      // max-files: oldest removed first; 0 = no limit
  std::uint64_t max_bytes = 0;      // max-bytes: same, by total size; 0 = no limit
  bool operator==(const FilesSink&) const = default;
};

struct ShmSink {         // type = "shm"
  std::string name;      // POSIX shm name, e.g. "/neuflow-front" (required, leading '/')
  int slots = 4;         // the latest N flows
  unsigned mode = 0640;  // shm-mode = "0640" (or 0o640): the segment's permissions
  bool operator==(const ShmSink&) const = default;
};

// The encoded (H.264) colour visualization. Exactly one of `file`, `rtsp`, `udp` is given.
struct VideoSink {  // type = "video"
  enum class Target { file, rtsp, udp };
  Target target = Target::file;
  std::filesystem::path file;  // file = ".../viz-%05d.mp4" (.mp4 or .mkv)
  int segment_seconds = 0;     // segment-seconds: a new file every N s; 0 = one file
  std::string rtsp_mount;      // rtsp = "/front": a mount on the [rtsp] server
  std::string udp_host;        // udp = "192.168.1.10:5000": RTP/H.264 over UDP
  int udp_port = 0;
  int bitrate_kbps = 2000;  // bitrate (kbit/s)
  double max_flow = 20.0;   // max-flow: px of full colour saturation
  bool operator==(const VideoSink&) const = default;
};

struct DisplaySink {  // type = "display": a window, for debugging
  double max_flow = 20.0;
  bool operator==(const DisplaySink&) const = default;
};

using SinkDescription = std::variant<FilesSink, ShmSink, VideoSink, DisplaySink>;

struct NamedSink {
  std::string name;  // unique in its graph: names the branch's elements, logs and metric labels
  SinkDescription settings;
  bool operator==(const NamedSink&) const = default;
};

struct GraphDescription {
  std::string name;  // the stream's name: names the RTSP channel, logs and metric labels
  SourceDescription source;
  FlowStage flow;
  std::vector<NamedSink> sinks;  // at least one
  bool operator==(const GraphDescription&) const = default;
};

}  // namespace neuflow::pipeline
