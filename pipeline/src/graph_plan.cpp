#include "neuflow/pipeline/graph_plan.hpp"

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <stdexcept>
#include <system_error>

namespace neuflow::pipeline {

namespace {

namespace fs = std::filesystem;

std::string caps_text(const std::string& media, const VideoMode& mode, const VideoMode& defaults = {}) {
  const int w = mode.width ? mode.width : defaults.width;
  const int h = mode.height ? mode.height : defaults.height;
  const int fn = mode.framerate_num ? mode.framerate_num : defaults.framerate_num;
  const int fd = mode.framerate_num ? mode.framerate_den : defaults.framerate_den;
  std::string caps = media;
  if (w) caps += ",width=" + std::to_string(w);
  if (h) caps += ",height=" + std::to_string(h);
  if (fn) caps += ",framerate=" + std::to_string(fn) + "/" + std::to_string(fd);
  return caps;
}

// Sinks do not wait for a first buffer before the pipeline may play (async=false): one branch
// that is slow to produce one (an H.264 encoder's lookahead) would otherwise hold every other
// sink in preroll while their queues fill, and the tee would stall the whole stream.
ElementSpec no_preroll(ElementSpec sink) { return sink.set("async", "false"); }

// Live outputs keep only the newest frames: a slow consumer loses frames, not the stream.
ElementSpec leaky_queue(const std::string& name) {
  return element("queue", name)
      .set("leaky", "downstream")
      .set("max-size-buffers", "2")
      .set("max-size-bytes", "0")
      .set("max-size-time", "0");
}

// The colour image of the flow alone (the element's default blends it over the video).
ElementSpec visualizer(const std::string& name, double max_flow) {
  return element("neuflowviz", name).set("mode", "flow").set("max-flow", std::to_string(max_flow));
}

// One H.264 setting for files, RTP/UDP and RTSP: live outputs trade compression for latency.
ElementSpec h264_encoder(const std::string& name, int bitrate_kbps, bool live) {
  ElementSpec enc = element("x264enc", name);
  if (live) enc.set("tune", "zerolatency");
  return enc.set("speed-preset", live ? "ultrafast" : "veryfast")
      .set("key-int-max", "30")
      // Keyframes every key-int-max frames only: a stream's first picture (no flow yet, drawn
      // white) and the next one (the first flow) looked like a scene cut, and the extra
      // keyframe left a segmented file's first segment with one frame that did not decode.
      .set("option-string", "scenecut=0")
      .set("bitrate", std::to_string(bitrate_kbps));
}

ElementSpec rtp_h264_payloader(const std::string& name) {
  return element("rtph264pay", name).set("pt", "96").set("config-interval", "1");
}

std::string with_index_pattern(const fs::path& file) {
  std::string s = file.string();
  if (s.find('%') != std::string::npos) return s;
  return (file.parent_path() / (file.stem().string() + "-%05d" + file.extension().string())).string();
}

ElementChain rtsp_media_chain(const std::string& channel, int bitrate_kbps) {
  return {element("intervideosrc").set("channel", channel), element("videoconvert"),
          caps_filter("video/x-raw,format=I420"), h264_encoder({}, bitrate_kbps, true), rtp_h264_payloader("pay0")};
}

}  // namespace

SourcePlan plan_source(const SourceDescription& source) {
  if (const auto* v = std::get_if<V4l2Source>(&source)) {
    ElementSpec src = element("v4l2src", "source").set("device", v->device);
    if (v->mjpeg) return {{src, caps_filter(caps_text("image/jpeg", v->mode)), element("jpegdec")}};
    return {{src, caps_filter(caps_text("video/x-raw", v->mode))}};
  }
  if (const auto* l = std::get_if<LibcameraSource>(&source)) {
    ElementSpec src = element("libcamerasrc", "source");
    if (!l->camera.empty()) src.set("camera-name", l->camera);
    return {{src, caps_filter(caps_text("video/x-raw", l->mode))}};
  }
  if (const auto* u = std::get_if<UriSource>(&source)) {
    return {{element("uridecodebin", "source").set("uri", u->uri)}, true};
  }
  const auto& t = std::get<TestSource>(source);
  ElementSpec src =
      element("videotestsrc", "source").set("pattern", t.pattern).set("is-live", t.live ? "true" : "false");
  if (t.frames >= 0) src.set("num-buffers", std::to_string(t.frames));
  return {{src, caps_filter(caps_text("video/x-raw", t.mode, VideoMode{320, 240, 30, 1}))}};
}

ElementChain plan_flow(const FlowStage& flow) {
  const model::SessionOptions& s = flow.session;
  return {element("videoconvert", "convert"),
          element("neuflow", "flow")
              .set("model", flow.model.string())
              .set("iters-s16", std::to_string(s.iterations.s16))
              .set("iters-s8", std::to_string(s.iterations.s8))
              .set("model-width", std::to_string(s.model_width))
              .set("model-height", std::to_string(s.model_height))
              .set("threads", std::to_string(s.threads))
              .set("behaviour", std::string(model::behaviour_name(flow.behaviour)))
              .set("channel-order", std::string(model::channel_order_name(s.network_order)))
              .set("backend", std::string(model::backend_name(s.backend)))
              .set("device", std::to_string(s.device))
              .set("precision", std::string(model::precision_name(s.precision)))
              .set("max-memory", std::to_string(s.max_memory_mb))
              .set("stats-interval", "0")};  // the counters are read as properties
}

std::string_view sink_kind(const SinkDescription& sink) {
  if (std::holds_alternative<FilesSink>(sink)) return "files";
  if (std::holds_alternative<ShmSink>(sink)) return "shm";
  if (std::holds_alternative<DisplaySink>(sink)) return "display";
  switch (std::get<VideoSink>(sink).target) {
    case VideoSink::Target::file: return "video-file";
    case VideoSink::Target::rtsp: return "rtsp";
    case VideoSink::Target::udp: return "udp";
  }
  return "video";
}

SinkPlan plan_sink(const std::string& graph, const NamedSink& sink, const PlanContext& context) {
  const std::string p = sink.name + "-";
  SinkPlan plan;
  plan.kind = sink_kind(sink.settings);
  if (const auto* f = std::get_if<FilesSink>(&sink.settings)) {
    const std::string pattern = (f->directory / ("flow_%08d." + f->format)).string();
    ElementSpec out = no_preroll(element("neuflowsink", p + "files"))
                          .set("location", pattern)
                          .set("index-location", (f->directory / "index.csv").string())
                          .set("index", std::to_string(context.first_free_index(pattern)));
    if (f->max_files) out.set("max-files", std::to_string(f->max_files));
    if (f->max_bytes) out.set("max-bytes", std::to_string(f->max_bytes));
    plan.chain = {element("queue", p + "queue"), out};
    plan.folders = {f->directory};
    return plan;
  }
  if (const auto* s = std::get_if<ShmSink>(&sink.settings)) {
    plan.chain = {leaky_queue(p + "queue"), no_preroll(element("neuflowshmsink", p + "shm"))
                                                .set("shm-name", s->name)
                                                .set("slots", std::to_string(s->slots))
                                                .set("shm-mode", std::to_string(s->mode))};
    return plan;
  }
  if (const auto* d = std::get_if<DisplaySink>(&sink.settings)) {
    const DisplayServer server = context.display_server();
    if (server == DisplayServer::none) throw std::runtime_error(no_display_reason());
    plan.chain = {leaky_queue(p + "queue"), visualizer(p + "viz", d->max_flow), element("videoconvert", p + "convert"),
                  no_preroll(element(server == DisplayServer::wayland ? "waylandsink" : "ximagesink", p + "display"))
                      .set("sync", "false")};
    return plan;
  }
  const auto& v = std::get<VideoSink>(sink.settings);
  switch (v.target) {
    case VideoSink::Target::file: {
      const std::string pattern = with_index_pattern(v.file);
      // The muxer and the file sink are given as elements (muxer-factory applies only with
      // async-finalize).
      ElementSpec mux = element("splitmuxsink", p + "mux")
                            .set("location", pattern)
                            .set("start-index", std::to_string(context.first_free_index(pattern)))
                            .set("max-size-time", std::to_string(static_cast<guint64>(v.segment_seconds) * GST_SECOND));
      mux.children = {{"muxer", element(v.file.extension() == ".mkv" ? "matroskamux" : "mp4mux", p + "muxer")},
                      {"sink", no_preroll(element("filesink", p + "file"))}};
      plan.chain = {element("queue", p + "queue"),          visualizer(p + "viz", v.max_flow),
                    element("videoconvert", p + "convert"), h264_encoder(p + "x264", v.bitrate_kbps, false),
                    element("h264parse", p + "parse"),      mux};
      if (!v.file.parent_path().empty()) plan.folders = {v.file.parent_path()};
      return plan;
    }
    case VideoSink::Target::rtsp:
      // Not synchronised to the clock: a flow leaves the network later than its frame's time,
      // so a synchronised sink would call most of them late and drop them with a warning; the
      // server's intervideosrc paces the clients.
      plan.chain = {leaky_queue(p + "queue"), visualizer(p + "viz", v.max_flow), element("videoconvert", p + "convert"),
                    no_preroll(element("intervideosink", p + "inter"))
                        .set("channel", rtsp_channel_name(graph, v.rtsp_mount))
                        .set("sync", "false")};
      return plan;
    case VideoSink::Target::udp:
      plan.chain = {leaky_queue(p + "queue"),
                    visualizer(p + "viz", v.max_flow),
                    element("videoconvert", p + "convert"),
                    h264_encoder(p + "x264", v.bitrate_kbps, true),
                    rtp_h264_payloader(p + "pay"),
                    element("udpsink", p + "udp")
                        .set("host", v.udp_host)
                        .set("port", std::to_string(v.udp_port))
                        .set("sync", "false")
                        .set("async", "false")};
      return plan;
  }
  throw std::logic_error("unknown video sink target");
}

std::vector<std::string> required_elements(const SourceDescription& source) {
  return factories_of(plan_source(source).chain);
}

std::vector<std::string> required_elements(const FlowStage& flow) { return factories_of(plan_flow(flow)); }

DisplayServer display_server_from_environment() {
  const auto set = [](const char* name) {
    const char* value = std::getenv(name);
    return value && *value;
  };
  if (set("WAYLAND_DISPLAY")) return DisplayServer::wayland;
  if (set("DISPLAY")) return DisplayServer::x11;
  return DisplayServer::none;
}

std::string no_display_reason() {
  return "no display to open a window on (neither WAYLAND_DISPLAY nor DISPLAY is set; a display sink needs a "
         "graphical session)";
}

std::vector<std::string> required_elements(const SinkDescription& sink) {
  // Without a display a display sink is cut off when its stream starts (neuflowd --check-config
  // warns): it needs nothing here.
  if (std::holds_alternative<DisplaySink>(sink) && display_server_from_environment() == DisplayServer::none) return {};
  ElementChain chain = plan_sink("graph", NamedSink{"sink", sink}).chain;
  if (const auto* v = std::get_if<VideoSink>(&sink); v && v->target == VideoSink::Target::rtsp) {
    const ElementChain server = rtsp_media_chain("channel", v->bitrate_kbps);
    chain.insert(chain.end(), server.begin(), server.end());
  }
  return factories_of(chain);
}

std::string rtsp_channel_name(const std::string& graph, const std::string& mount) {
  return "neuflowd/" + graph + mount;
}

std::string rtsp_launch_line(const std::string& channel, int bitrate_kbps) {
  return "( " + launch_text(rtsp_media_chain(channel, bitrate_kbps)) + " )";
}

int next_free_index(const std::string& pattern) {
  const fs::path p(pattern);
  const std::string name = p.filename().string();
  const auto percent = name.find('%');
  if (percent == std::string::npos) return 0;
  const auto conv_end = name.find('d', percent);
  if (conv_end == std::string::npos) return 0;
  const std::string prefix = name.substr(0, percent), suffix = name.substr(conv_end + 1);
  const fs::path dir = p.parent_path().empty() ? fs::path(".") : p.parent_path();
  std::error_code ec;
  int next = 0;
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string f = it->path().filename().string();
    if (f.size() <= prefix.size() + suffix.size() || f.compare(0, prefix.size(), prefix) != 0 ||
        f.compare(f.size() - suffix.size(), suffix.size(), suffix) != 0) {
      continue;
    }
    const std::string digits = f.substr(prefix.size(), f.size() - prefix.size() - suffix.size());
    if (digits.empty() || digits.size() > 9 ||
        !std::all_of(digits.begin(), digits.end(), [](unsigned char c) { return std::isdigit(c) != 0; })) {
      continue;
    }
    next = std::max(next, std::stoi(digits) + 1);
  }
  return next;
}

}  // namespace neuflow::pipeline
