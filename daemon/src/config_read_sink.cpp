// [[stream.sink]]: flow files, a shared-memory ring, an encoded visualization (file, RTSP
// mount or RTP/UDP) or a window.
#include <array>
#include <climits>
#include <limits>
#include <vector>

#include "config_read.hpp"
#include "config_values.hpp"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {
namespace {

using Need = TableReader::Need;

constexpr std::int64_t max_int64 = std::numeric_limits<std::int64_t>::max();
// neuflowviz's own limit.
constexpr double max_max_flow = 1e6;

FilesSink read_files(const TableReader& t, const std::string& user, ReadContext& context) {
  static constexpr std::array<std::string_view, 6> keys = {"type",   "name",      "directory",
                                                           "format", "max-files", "max-bytes"};
  static constexpr std::array<std::string_view, 3> formats = {"flo", "npy", "png"};
  t.allow_only(keys);
  FilesSink f;
  if (auto directory = t.string("directory", Need::required)) {
    if (directory->empty()) {
      t.report("directory", "expected the folder to write flow files into, got an empty string");
    } else {
      f.directory =
          context.need_path(PathNeed::Kind::writable_directory, *directory, "directory", t.position("directory"));
      context.unique.claim("output directory", f.directory.string(), user, t.position("directory"), context.issues);
    }
  }
  if (auto format = t.choice("format", formats)) f.format = *format;
  if (auto v = t.integer("max-files", 0, max_int64)) f.max_files = static_cast<std::uint64_t>(*v);
  if (auto v = t.integer("max-bytes", 0, max_int64)) f.max_bytes = static_cast<std::uint64_t>(*v);
  return f;
}

ShmSink read_shm(const TableReader& t, const std::string& user, ReadContext& context) {
  static constexpr std::array<std::string_view, 5> keys = {"type", "name", "shm-name", "slots", "shm-mode"};
  t.allow_only(keys);
  ShmSink s;
  if (auto name = t.string("shm-name", Need::required)) {
    if (const auto problem = check_shm_name(*name); !problem.empty()) {
      t.report("shm-name", "expected " + problem + ", got \"" + *name + "\"");
    } else {
      s.name = *name;
      context.unique.claim("shared-memory name", s.name, user, t.position("shm-name"), context.issues);
    }
  }
  if (auto v = t.integer("slots", 1, 64)) s.slots = static_cast<int>(*v);
  if (const auto* node = t.get("shm-mode")) {
    std::optional<unsigned> mode;
    if (const auto* text = node->as_string()) mode = parse_octal_mode(text->get());
    if (const auto* number = node->as_integer(); number && number->get() >= 0 && number->get() <= 07777) {
      mode = static_cast<unsigned>(number->get());
    }
    if (mode && check_shm_mode(*mode).empty()) {
      s.mode = *mode;
    } else {
      t.report("shm-mode", "expected " + check_shm_mode(07777) + ", got " + describe_value(*node));
    }
  }
  return s;
}

// The one of file / rtsp / udp that is given.
void read_video_target(const TableReader& t, const std::string& user, ReadContext& context, VideoSink& v) {
  std::vector<std::string_view> given;
  for (const std::string_view key : {"file", "rtsp", "udp"}) {
    if (t.has(key)) given.push_back(key);
  }
  if (given.empty()) {
    t.report_here(
        "missing the video sink's target in [[stream.sink]]: expected exactly one of file = "
        "\"viz-%05d.mp4\", rtsp = \"/mount\" or udp = \"host:port\"");
    return;
  }
  if (given.size() > 1) {
    t.report(given[1], "give exactly one of file, rtsp, udp; " + std::string(given[0]) + " is already set");
    return;
  }
  const std::string_view key = given[0];
  const auto text = t.string(key);
  if (!text) return;
  if (key == "file") {
    v.target = VideoSink::Target::file;
    const std::filesystem::path written(*text);
    const auto extension = written.extension();
    if (extension != ".mp4" && extension != ".mkv") {
      t.report("file", "expected a file name ending in .mp4 or .mkv, got \"" + *text + "\"");
      return;
    }
    if (const auto problem = check_index_pattern(written.filename().string()); !problem.empty()) {
      t.report("file", "expected " + problem + ", got \"" + *text + "\"");
      return;
    }
    v.file = resolve_path(context.folder, *text);
    context.need_path(PathNeed::Kind::writable_directory, written.parent_path().string(), "file", t.position("file"));
    context.unique.claim("video file", v.file.string(), user, t.position("file"), context.issues);
  } else if (key == "rtsp") {
    v.target = VideoSink::Target::rtsp;
    if (const auto problem = check_rtsp_mount(*text); !problem.empty()) {
      t.report("rtsp", "expected " + problem + ", got \"" + *text + "\"");
      return;
    }
    v.rtsp_mount = *text;
    if (!context.has_rtsp_server) {
      t.report("rtsp",
               "a video sink on an RTSP mount needs the server: add an [rtsp] table, e.g. [rtsp] "
               "listen = \"0.0.0.0:8554\"");
    }
    context.unique.claim("RTSP mount", v.rtsp_mount, user, t.position("rtsp"), context.issues);
  } else {
    v.target = VideoSink::Target::udp;
    std::string error;
    const auto address = parse_host_port(*text, error);
    if (!address) {
      t.report("udp", "expected " + error + ", got \"" + *text + "\"");
      return;
    }
    v.udp_host = address->host;
    v.udp_port = address->port;
  }
}

VideoSink read_video(const TableReader& t, const std::string& user, ReadContext& context) {
  static constexpr std::array<std::string_view, 8> keys = {"type", "name",    "file",     "rtsp",
                                                           "udp",  "bitrate", "max-flow", "segment-seconds"};
  t.allow_only(keys);
  VideoSink v;
  read_video_target(t, user, context, v);
  // x264enc's range, in kbit/s.
  if (auto bitrate = t.integer("bitrate", 1, 2048000)) v.bitrate_kbps = static_cast<int>(*bitrate);
  if (auto max_flow = t.number("max-flow", 0.0, max_max_flow)) v.max_flow = *max_flow;
  if (auto seconds = t.integer("segment-seconds", 0, INT_MAX)) {
    v.segment_seconds = static_cast<int>(*seconds);
    if (!t.has("file")) t.report("segment-seconds", "applies only to a video sink with file = \"...\"");
  }
  return v;
}

DisplaySink read_display(const TableReader& t) {
  static constexpr std::array<std::string_view, 3> keys = {"type", "name", "max-flow"};
  t.allow_only(keys);
  DisplaySink d;
  if (auto max_flow = t.number("max-flow", 0.0, max_max_flow)) d.max_flow = *max_flow;
  return d;
}

}  // namespace

bool read_sink(const TableReader& t, std::size_t index, const std::string& stream, ReadContext& context,
               SinkConfig& out) {
  static constexpr std::array<std::string_view, 4> types = {"files", "shm", "video", "display"};
  out.where = t.where();
  const auto type = t.choice("type", types, Need::required);
  // Without a known type the valid keys are unknown too: only the type is reported.
  if (!type) return false;
  out.name = *type + "-" + std::to_string(index);
  if (auto name = t.string("name")) {
    if (const auto problem = check_name(*name); !problem.empty()) {
      t.report("name", "expected " + problem + ", got \"" + *name + "\"");
    } else {
      out.name = *name;
    }
  }
  const std::string user = "the " + *type + " sink '" + out.name + "' of stream '" + stream + "'";
  if (*type == "files") out.settings = read_files(t, user, context);
  if (*type == "shm") out.settings = read_shm(t, user, context);
  if (*type == "video") out.settings = read_video(t, user, context);
  if (*type == "display") {
    out.settings = read_display(t);
    context.needs.displays.push_back({user, t.position("type")});
  }
  context.need_elements(pipeline::required_elements(out.settings), user, out.where);
  return true;
}

}  // namespace neuflow::daemon
