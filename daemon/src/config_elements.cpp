#include "config_elements.hpp"

#include <variant>

namespace neuflow::daemon {

std::vector<std::string> elements_for(const SourceSettings& source) {
  if (const auto* v4l2 = std::get_if<V4l2Source>(&source)) {
    if (v4l2->mjpeg) return {"v4l2src", "jpegdec"};
    return {"v4l2src"};
  }
  if (std::holds_alternative<LibcameraSource>(source)) return {"libcamerasrc"};
  if (std::holds_alternative<UriSource>(source)) return {"uridecodebin"};
  return {"videotestsrc"};
}

std::vector<std::string> elements_for_flow() { return {"videoconvert", "neuflow"}; }

std::vector<std::string> elements_for(const SinkSettings& sink) {
  if (std::holds_alternative<FilesSink>(sink)) return {"neuflowsink"};
  if (std::holds_alternative<ShmSink>(sink)) return {"neuflowshmsink"};
  if (std::holds_alternative<DisplaySink>(sink)) return {"neuflowviz", "videoconvert", "autovideosink"};
  const auto& video = std::get<VideoSink>(sink);
  switch (video.target) {
    case VideoSink::Target::file: {
      const char* muxer = video.file.extension() == ".mkv" ? "matroskamux" : "mp4mux";
      return {"neuflowviz", "videoconvert", "x264enc", "h264parse", "splitmuxsink", muxer};
    }
    case VideoSink::Target::rtsp:
      // The RTSP server's side of the channel encodes and packetizes.
      return {"neuflowviz", "videoconvert", "intervideosink", "intervideosrc", "x264enc", "rtph264pay"};
    case VideoSink::Target::udp:
      return {"neuflowviz", "videoconvert", "x264enc", "rtph264pay", "udpsink"};
  }
  return {};
}

bool is_neuflow_element(const std::string& factory) { return factory.starts_with("neuflow"); }

}  // namespace neuflow::daemon
