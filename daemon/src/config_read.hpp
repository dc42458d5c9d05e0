#pragma once
// A parsed TOML document → Config (internal to the config loader): the schema of every table,
// the defaults, and the rules between streams. Everything wrong goes to Issues, and reading goes
// on, so one run reports it all. What the file asks of the machine (files, devices, GStreamer
// elements) is only noted here, as MachineNeeds, and checked by config_environment.
#include <toml++/toml.h>

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "config.hpp"
#include "config_issues.hpp"
#include "config_toml.hpp"

namespace neuflow::daemon {

struct PathNeed {
  enum class Kind {
    readable_file,       // an input video, a credentials file
    checkpoint,          // the model: readable, and a NeuFlow-V2 checkpoint
    video_device,        // a V4L2 device node
    writable_directory,  // exists and is writable, or can be created
  };
  Kind kind = Kind::readable_file;
  std::filesystem::path path;  // absolute
  std::string written;         // as in the file, for messages when it was relative
  std::string key;
  SourcePosition where;
};

struct ElementNeed {
  std::string factory;  // "x264enc"
  std::string user;     // "the video sink 'video-1' of stream 'front'"
  SourcePosition where;
};

struct UriSchemeNeed {
  std::string scheme;  // "rtsp"
  std::string user;
  SourcePosition where;
};

// backend = "vulkan": the device must exist (and Vulkan with it).
struct GpuNeed {
  int device = -1;   // -1: any
  std::string user;  // "stream 'front'"
  SourcePosition where;
};

// type = "display": a window needs a graphical session.
struct DisplayNeed {
  std::string user;  // "the display sink 'screen' of stream 'front'"
  SourcePosition where;
};

struct MachineNeeds {
  std::vector<PathNeed> paths;
  std::vector<DisplayNeed> displays;
  std::vector<GpuNeed> gpus;
  std::vector<ElementNeed> elements;
  std::vector<UriSchemeNeed> uri_schemes;
};

struct ReadResult {
  Config config;
  MachineNeeds needs;
};

// `file` names the file in the Config; relative paths are resolved against its folder.
ReadResult read_config(const toml::table& root, const std::filesystem::path& file, Issues& issues);

// ---- shared by the per-table readers -------------------------------------------------------

// Values that must be unique across the whole file (shm names, RTSP mounts, output paths).
class UniqueValues {
 public:
  // False, after reporting at `where`, when `value` of `kind` was claimed before.
  bool claim(const std::string& kind, const std::string& value, const std::string& user, SourcePosition where,
             Issues& issues);

 private:
  struct Claim {
    std::string user;
    SourcePosition where;
  };
  std::map<std::pair<std::string, std::string>, Claim> claims_;
};

struct ReadContext {
  std::filesystem::path folder;  // the config file's folder, absolute
  Issues& issues;
  MachineNeeds& needs;
  bool has_rtsp_server = false;  // an [rtsp] table is present
  UniqueValues unique;

  void need_elements(const std::vector<std::string>& factories, const std::string& user, SourcePosition where);
  // Resolves `written` against the config's folder and notes the path for the machine check.
  std::filesystem::path need_path(PathNeed::Kind kind, const std::string& written, const std::string& key,
                                  SourcePosition where);
};

// One [[stream]] (name, [stream.source], [stream.flow], [[stream.sink]]). `index` counts from 0.
StreamConfig read_stream(const TableReader& stream, std::size_t index, ReadContext& context);
SourceConfig read_source(const TableReader& source, const std::string& stream, ReadContext& context);
// `stream` names the stream in messages.
FlowConfig read_flow(const TableReader& flow, const std::string& stream, ReadContext& context);
// Returns false when the sink could not be read well enough to keep (its type is unknown).
bool read_sink(const TableReader& sink, std::size_t index, const std::string& stream, ReadContext& context,
               SinkConfig& out);

}  // namespace neuflow::daemon
