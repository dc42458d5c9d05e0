#include "config_environment.hpp"

#include <fcntl.h>
#include <gst/gst.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <map>
#include <optional>
#include <set>
#include <string>

#include "neuflow/model/architecture.hpp"
#include "neuflow/model/checkpoint.hpp"
#include "neuflow/model/gpu_devices.hpp"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {
namespace {

// The elements of this project's plugin (libgstneuflow.so).
bool is_neuflow_element(const std::string& factory) { return factory.starts_with("neuflow"); }

namespace fs = std::filesystem;

std::string quoted(const fs::path& path) { return "\"" + path.string() + "\""; }

// Names the path as resolved, and how, when the file gave it relative to its own folder.
std::string described(const PathNeed& need) {
  std::string text = quoted(need.path);
  if (!need.written.empty() && !fs::path(need.written).is_absolute() && need.written.find("://") == std::string::npos) {
    text += " (\"" + need.written + "\" relative to the config file's folder)";
  }
  return text;
}

void report(const PathNeed& need, Issues& issues, const std::string& problem) {
  issues.add(need.where, need.key + ": " + described(need) + " " + problem);
}

std::string missing_or(int error) {
  return error == ENOENT || error == ENOTDIR ? "does not exist"
                                             : std::string("cannot be reached: ") + std::strerror(error);
}

void check_readable_file(const PathNeed& need, Issues& issues) {
  struct stat st {};
  if (::stat(need.path.c_str(), &st) != 0) {
    const int error = errno;
    if (need.key == "model" && error == ENOENT) {
      const std::string fetch = "neuflow fetch-model mixed -o " + need.path.parent_path().string();
      return report(need, issues,
                    need.path.filename() == "neuflow_mixed.pth"
                        ? "does not exist: download the published weights with `" + fetch + "`"
                        : "does not exist: `" + fetch +
                              "` downloads the published weights as neuflow_mixed.pth "
                              "(point model at it), or copy a NeuFlow-V2 checkpoint here");
    }
    return report(need, issues, missing_or(error));
  }
  if (S_ISDIR(st.st_mode)) return report(need, issues, "is a folder, expected a file");
  if (!S_ISREG(st.st_mode)) return report(need, issues, "is not a regular file");
  const int fd = ::open(need.path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return report(need, issues, std::string("cannot be read by this user: ") + std::strerror(errno));
  ::close(fd);
}

// Readable (else a warning), then the checkpoint reader's container, pickle and storage-size
// checks and the architecture check, without reading the weights (36 MB).
void check_checkpoint(const PathNeed& need, Issues& issues, Issues& errors) {
  const std::size_t before = issues.size();
  check_readable_file(need, issues);
  if (issues.size() != before) return;
  std::optional<std::string> problem;
  try {
    problem = model::find_architecture_mismatch(model::read_checkpoint_header(need.path));
  } catch (const model::CheckpointError& e) {
    // The loader names the file; the message names it already.
    std::string what = e.what();
    if (const auto colon = what.find("': "); colon != std::string::npos) what.erase(0, colon + 3);
    problem = what;
  }
  if (problem) report(need, errors, "is not a NeuFlow-V2 checkpoint: " + *problem);
}

void check_video_device(const PathNeed& need, Issues& issues) {
  struct stat st {};
  if (::stat(need.path.c_str(), &st) != 0) {
    const int error = errno;
    if (error == ENOENT) return report(need, issues, "does not exist: is the camera connected? (ls /dev/video*)");
    return report(need, issues, missing_or(error));
  }
  if (!S_ISCHR(st.st_mode))
    return report(need, issues, "is not a device node; expected a V4L2 device like /dev/video0");
  if (::access(need.path.c_str(), R_OK | W_OK) != 0) {
    report(need, issues,
           std::string("cannot be opened for reading and writing (") + std::strerror(errno) +
               "): add the daemon's user to the group that owns it (usually 'video')");
  }
}

void check_writable_directory(const PathNeed& need, Issues& issues) {
  struct stat st {};
  if (::stat(need.path.c_str(), &st) == 0) {
    if (!S_ISDIR(st.st_mode)) return report(need, issues, "exists but is not a folder");
    if (::access(need.path.c_str(), W_OK | X_OK) != 0) {
      report(need, issues, std::string("is not writable by this user: ") + std::strerror(errno));
    }
    return;
  }
  // ENOTDIR: a file where a folder should be on the way; the walk below names it.
  if (errno != ENOENT && errno != ENOTDIR) return report(need, issues, missing_or(errno));
  // Created at start: the nearest folder that exists must let us create the rest.
  for (fs::path parent = need.path.parent_path(); !parent.empty(); parent = parent.parent_path()) {
    if (::stat(parent.c_str(), &st) != 0) {
      if ((errno == ENOENT || errno == ENOTDIR) && parent != parent.root_path()) continue;
      return report(need, issues, "cannot be created: " + quoted(parent) + " " + missing_or(errno));
    }
    if (!S_ISDIR(st.st_mode)) {
      return report(need, issues, "cannot be created: " + quoted(parent) + " is not a folder");
    }
    if (::access(parent.c_str(), W_OK | X_OK) != 0) {
      return report(need, issues,
                    "does not exist and cannot be created: " + quoted(parent) + " is not writable by this user");
    }
    return;
  }
}

std::string debian_package(const std::string& factory) {
  static const std::map<std::string, std::string> packages = {
      {"v4l2src", "gstreamer1.0-plugins-good"},
      {"jpegdec", "gstreamer1.0-plugins-good"},
      {"splitmuxsink", "gstreamer1.0-plugins-good"},
      {"mp4mux", "gstreamer1.0-plugins-good"},
      {"matroskamux", "gstreamer1.0-plugins-good"},
      {"rtph264pay", "gstreamer1.0-plugins-good"},
      {"udpsink", "gstreamer1.0-plugins-good"},
      {"waylandsink", "gstreamer1.0-plugins-bad"},
      {"ximagesink", "gstreamer1.0-x"},
      {"libcamerasrc", "gstreamer1.0-libcamera"},
      {"uridecodebin", "gstreamer1.0-plugins-base"},
      {"videotestsrc", "gstreamer1.0-plugins-base"},
      {"videoconvert", "gstreamer1.0-plugins-base"},
      {"x264enc", "gstreamer1.0-plugins-ugly"},
      {"h264parse", "gstreamer1.0-plugins-bad"},
      {"intervideosink", "gstreamer1.0-plugins-bad"},
      {"intervideosrc", "gstreamer1.0-plugins-bad"},
  };
  const auto it = packages.find(factory);
  return it == packages.end() ? std::string() : it->second;
}

// ", and 2 more" after the first user of something missing.
std::string more(std::size_t users) {
  return users > 1 ? " (and " + std::to_string(users - 1) + " more)" : std::string();
}

void check_elements(const std::vector<ElementNeed>& needs, const GstInventory& gstreamer, Issues& issues) {
  // Each missing element once, where it is first needed.
  std::vector<std::string> order;
  std::map<std::string, std::vector<const ElementNeed*>> users;
  for (const auto& need : needs) {
    auto& list = users[need.factory];
    if (list.empty()) order.push_back(need.factory);
    list.push_back(&need);
  }
  const bool plugin_found = gstreamer.has_element("neuflow");
  bool plugin_reported = false;
  for (const auto& factory : order) {
    if (gstreamer.has_element(factory)) continue;
    const auto& list = users[factory];
    const ElementNeed& first = *list.front();
    if (is_neuflow_element(factory) && !plugin_found) {
      if (plugin_reported) continue;
      plugin_reported = true;
      issues.add(first.where, "the neuflow GStreamer plugin (libgstneuflow.so), needed by " + first.user +
                                  ", was not found: install it (cmake --install) or set GST_PLUGIN_PATH to the "
                                  "folder that holds libgstneuflow.so");
      continue;
    }
    if (is_neuflow_element(factory)) {
      issues.add(first.where, "GStreamer element '" + factory + "', needed by " + first.user + more(list.size()) +
                                  ", is not in the installed neuflow plugin, which is older than this neuflowd: "
                                  "install the plugin built with it, or set GST_PLUGIN_PATH to its folder");
      continue;
    }
    std::string message =
        "GStreamer element '" + factory + "', needed by " + first.user + more(list.size()) + ", is not installed";
    if (const auto package = debian_package(factory); !package.empty()) {
      message += " (Debian: apt install " + package + ")";
    }
    issues.add(first.where, message);
  }
}

// backend = "vulkan" waits (like a missing camera) until Vulkan and its device are there.
void check_gpus(const std::vector<GpuNeed>& needs, Issues& issues) {
  if (needs.empty()) return;
  std::vector<model::GpuDevice> devices;
  std::string unavailable;
  try {
    devices = model::list_gpu_devices();
  } catch (const model::BackendError& e) {
    unavailable = e.what();
  }
  for (const auto& need : needs) {
    if (!unavailable.empty()) {
      issues.add(need.where, "backend: " + need.user + " runs on Vulkan, but " + unavailable);
    } else if (devices.empty()) {
      issues.add(need.where, "backend: " + need.user +
                                 " runs on Vulkan, but Vulkan has no device here (install the GPU's Vulkan driver; "
                                 "`neuflow devices` lists what Vulkan sees)");
    } else if (need.device >= static_cast<int>(devices.size())) {
      issues.add(need.where, "device: " + need.user + " asks for Vulkan device " + std::to_string(need.device) +
                                 ", but this machine has " + std::to_string(devices.size()) + " (0 to " +
                                 std::to_string(devices.size() - 1) + "; `neuflow devices` lists them)");
    }
  }
}

// A display sink where there is no display is cut off at start (its stream goes on): say so now.
void check_displays(const std::vector<DisplayNeed>& needs, Issues& issues) {
  if (pipeline::display_server_from_environment() != pipeline::DisplayServer::none) return;
  for (const auto& need : needs) {
    issues.add(need.where, "type: " + need.user + " shows a window, but there is " + pipeline::no_display_reason() +
                               ": it will be cut off when the stream starts, and the stream's other sinks go on");
  }
}

void check_uri_schemes(const std::vector<UriSchemeNeed>& needs, const GstInventory& gstreamer, Issues& issues) {
  std::set<std::string> reported;
  for (const auto& need : needs) {
    if (gstreamer.reads_uri_scheme(need.scheme) || !reported.insert(need.scheme).second) continue;
    std::string message =
        "uri: no installed GStreamer element reads \"" + need.scheme + "://\" URIs, needed by " + need.user;
    const std::string& scheme = need.scheme;
    if (scheme == "rtsp" || scheme == "rtsps" || scheme == "rtspt" || scheme == "http" || scheme == "https") {
      message += " (Debian: apt install gstreamer1.0-plugins-good)";
    }
    issues.add(need.where, message);
  }
}

}  // namespace

GstInventory installed_gstreamer() {
  return GstInventory{
      [](const std::string& factory) {
        GstElementFactory* found = gst_element_factory_find(factory.c_str());
        if (found) gst_object_unref(found);
        return found != nullptr;
      },
      [](const std::string& scheme) { return gst_uri_protocol_is_supported(GST_URI_SRC, scheme.c_str()) != FALSE; },
  };
}

void check_machine(const MachineNeeds& needs, const GstInventory& gstreamer, Issues& issues, Issues& errors) {
  for (const auto& need : needs.paths) {
    switch (need.kind) {
      case PathNeed::Kind::readable_file: check_readable_file(need, issues); break;
      case PathNeed::Kind::checkpoint: check_checkpoint(need, issues, errors); break;
      case PathNeed::Kind::video_device: check_video_device(need, issues); break;
      case PathNeed::Kind::writable_directory: check_writable_directory(need, issues); break;
    }
  }
  check_elements(needs.elements, gstreamer, issues);
  check_uri_schemes(needs.uri_schemes, gstreamer, issues);
  check_gpus(needs.gpus, issues);
  check_displays(needs.displays, issues);
}

}  // namespace neuflow::daemon
