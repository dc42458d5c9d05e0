#include "stream_graph.hpp"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <stdexcept>
#include <system_error>

namespace neuflow::daemon {

namespace {

namespace fs = std::filesystem;

GstElement* make(const char* factory, const std::string& name = {}) {
  GstElement* e = gst_element_factory_make(factory, name.empty() ? nullptr : name.c_str());
  if (!e) {
    throw std::runtime_error(std::string("the GStreamer element '") + factory +
                             "' is not installed (or the neuflow plugin is not on GST_PLUGIN_PATH)");
  }
  return e;
}

// Properties are set from their string form so GStreamer converts to the property's own type
// (guint, enums by nick, doubles) — no varargs type mismatches.
void set(GstElement* e, const char* property, const std::string& value) {
  if (!g_object_class_find_property(G_OBJECT_GET_CLASS(e), property)) {
    throw std::runtime_error(std::string("element ") + GST_ELEMENT_NAME(e) + " has no property '" + property +
                             "' (is the installed plugin older than neuflowd?)");
  }
  gst_util_set_object_arg(G_OBJECT(e), property, value.c_str());
}

void link(GstElement* a, GstElement* b) {
  if (!gst_element_link(a, b)) {
    throw std::runtime_error(std::string("cannot link ") + GST_ELEMENT_NAME(a) + " to " + GST_ELEMENT_NAME(b));
  }
}

// Adds the elements to `bin` and links them in order.
void add_chain(GstBin* bin, std::initializer_list<GstElement*> chain) {
  GstElement* prev = nullptr;
  for (GstElement* e : chain) {
    gst_bin_add(bin, e);
    if (prev) link(prev, e);
    prev = e;
  }
}

GstElement* capsfilter(const std::string& media, const VideoMode& mode, const VideoMode& defaults = {}) {
  GstCaps* caps = gst_caps_new_empty_simple(media.c_str());
  const int w = mode.width ? mode.width : defaults.width;
  const int h = mode.height ? mode.height : defaults.height;
  const int fn = mode.framerate_num ? mode.framerate_num : defaults.framerate_num;
  const int fd = mode.framerate_num ? mode.framerate_den : defaults.framerate_den;
  if (w) gst_caps_set_simple(caps, "width", G_TYPE_INT, w, nullptr);
  if (h) gst_caps_set_simple(caps, "height", G_TYPE_INT, h, nullptr);
  if (fn) gst_caps_set_simple(caps, "framerate", GST_TYPE_FRACTION, fn, fd, nullptr);
  GstElement* f = make("capsfilter");
  g_object_set(f, "caps", caps, nullptr);
  gst_caps_unref(caps);
  return f;
}

// uridecodebin's pads appear once the stream is typed; link the first video one.
void on_decoded_pad(GstElement*, GstPad* pad, gpointer user_data) {
  auto* convert = static_cast<GstElement*>(user_data);
  GstCaps* caps = gst_pad_get_current_caps(pad);
  if (!caps) caps = gst_pad_query_caps(pad, nullptr);
  const bool video = caps && gst_caps_get_size(caps) > 0 &&
                     g_str_has_prefix(gst_structure_get_name(gst_caps_get_structure(caps, 0)), "video/");
  if (caps) gst_caps_unref(caps);
  if (!video) return;  // audio and subtitles are left unlinked
  GstPad* sink = gst_element_get_static_pad(convert, "sink");
  if (!gst_pad_is_linked(sink)) gst_pad_link(pad, sink);
  gst_object_unref(sink);
}

// Source elements into `pipeline`; returns the element whose src pad feeds videoconvert, or
// nullptr when the source links itself later (uridecodebin).
GstElement* add_source(GstBin* pipeline, const SourceConfig& source, GstElement* convert) {
  if (const auto* v = std::get_if<V4l2Source>(&source.settings)) {
    GstElement* src = make("v4l2src", "source");
    set(src, "device", v->device);
    if (v->mjpeg) {
      GstElement* caps = capsfilter("image/jpeg", v->mode);
      GstElement* dec = make("jpegdec");
      add_chain(pipeline, {src, caps, dec});
      return dec;
    }
    GstElement* caps = capsfilter("video/x-raw", v->mode);
    add_chain(pipeline, {src, caps});
    return caps;
  }
  if (const auto* l = std::get_if<LibcameraSource>(&source.settings)) {
    GstElement* src = make("libcamerasrc", "source");
    if (!l->camera.empty()) set(src, "camera-name", l->camera);
    GstElement* caps = capsfilter("video/x-raw", l->mode);
    add_chain(pipeline, {src, caps});
    return caps;
  }
  if (const auto* u = std::get_if<UriSource>(&source.settings)) {
    GstElement* src = make("uridecodebin", "source");
    set(src, "uri", u->uri);
    gst_bin_add(pipeline, src);
    g_signal_connect(src, "pad-added", G_CALLBACK(on_decoded_pad), convert);
    return nullptr;
  }
  const auto& t = std::get<TestSource>(source.settings);
  GstElement* src = make("videotestsrc", "source");
  set(src, "pattern", t.pattern);
  set(src, "is-live", t.live ? "true" : "false");
  if (t.frames >= 0) set(src, "num-buffers", std::to_string(t.frames));
  GstElement* caps = capsfilter("video/x-raw", t.mode, VideoMode{320, 240, 30, 1});
  add_chain(pipeline, {src, caps});
  return caps;
}

std::string with_index_pattern(const fs::path& file) {
  const std::string s = file.string();
  if (s.find('%') != std::string::npos) return s;
  return (file.parent_path() / (file.stem().string() + "-%05d" + file.extension().string())).string();
}

GstElement* visualizer(const std::string& name, double max_flow) {
  GstElement* viz = make("neuflowviz", name);
  set(viz, "max-flow", std::to_string(max_flow));
  return viz;
}

GstElement* h264_encoder(const std::string& name, int bitrate_kbps, bool live) {
  GstElement* enc = make("x264enc", name);
  set(enc, "bitrate", std::to_string(bitrate_kbps));
  set(enc, "speed-preset", live ? "ultrafast" : "veryfast");
  if (live) set(enc, "tune", "zerolatency");
  set(enc, "key-int-max", "30");
  return enc;
}

// Sinks do not wait for a first buffer before the pipeline may play (async=false): one branch
// that is slow to produce one (an H.264 encoder's lookahead) would otherwise hold every other
// sink in preroll while their queues fill, and the tee would stall the whole stream.
GstElement* no_preroll(GstElement* sink) {
  set(sink, "async", "false");
  return sink;
}

GstElement* leaky_queue(const std::string& name) {
  GstElement* q = make("queue", name);
  set(q, "leaky", "downstream");
  set(q, "max-size-buffers", "2");
  set(q, "max-size-bytes", "0");
  set(q, "max-size-time", "0");
  return q;
}

// The elements of one sink branch, inside `bin`; returns the branch's first element.
GstElement* fill_branch(GstBin* bin, const std::string& stream, const SinkConfig& sink) {
  const std::string p = sink.name + "-";
  if (const auto* f = std::get_if<FilesSink>(&sink.settings)) {
    std::error_code ec;
    fs::create_directories(f->directory, ec);
    if (ec) throw std::runtime_error("cannot create " + f->directory.string() + ": " + ec.message());
    const std::string pattern = (f->directory / ("flow_%08d." + f->format)).string();
    GstElement* q = make("queue", p + "queue");
    GstElement* out = no_preroll(make("neuflowsink", p + "files"));
    set(out, "location", pattern);
    set(out, "index-location", (f->directory / "index.csv").string());
    set(out, "index", std::to_string(next_free_index(pattern)));
    if (f->max_files) set(out, "max-files", std::to_string(f->max_files));
    if (f->max_bytes) set(out, "max-bytes", std::to_string(f->max_bytes));
    add_chain(bin, {q, out});
    return q;
  }
  if (const auto* s = std::get_if<ShmSink>(&sink.settings)) {
    GstElement* q = leaky_queue(p + "queue");
    GstElement* out = no_preroll(make("neuflowshmsink", p + "shm"));
    set(out, "shm-name", s->name);
    set(out, "slots", std::to_string(s->slots));
    set(out, "shm-mode", std::to_string(s->mode));
    add_chain(bin, {q, out});
    return q;
  }
  if (const auto* d = std::get_if<DisplaySink>(&sink.settings)) {
    GstElement* q = leaky_queue(p + "queue");
    GstElement* out = make("autovideosink", p + "display");
    set(out, "sync", "false");
    set(out, "async-handling", "true");  // a bin: it has no `async`, but settles its own preroll
    add_chain(bin, {q, visualizer(p + "viz", d->max_flow), make("videoconvert", p + "convert"), out});
    return q;
  }
  const auto& v = std::get<VideoSink>(sink.settings);
  switch (v.target) {
    case VideoSink::Target::file: {
      std::error_code ec;
      if (!v.file.parent_path().empty()) fs::create_directories(v.file.parent_path(), ec);
      if (ec) throw std::runtime_error("cannot create " + v.file.parent_path().string() + ": " + ec.message());
      const std::string pattern = with_index_pattern(v.file);
      GstElement* q = make("queue", p + "queue");
      GstElement* mux = make("splitmuxsink", p + "mux");
      set(mux, "location", pattern);
      set(mux, "start-index", std::to_string(next_free_index(pattern)));
      // (muxer-factory only applies with async-finalize; the muxer and sink are given as elements.)
      GstElement* muxer = make(v.file.extension() == ".mkv" ? "matroskamux" : "mp4mux", p + "muxer");
      GstElement* file = no_preroll(make("filesink", p + "file"));
      g_object_set(mux, "muxer", muxer, "sink", file, nullptr);
      set(mux, "max-size-time", std::to_string(static_cast<guint64>(v.segment_seconds) * GST_SECOND));
      add_chain(bin, {q, visualizer(p + "viz", v.max_flow), make("videoconvert", p + "convert"),
                      h264_encoder(p + "x264", v.bitrate_kbps, false), make("h264parse", p + "parse"), mux});
      return q;
    }
    case VideoSink::Target::rtsp: {
      GstElement* q = leaky_queue(p + "queue");
      GstElement* out = no_preroll(make("intervideosink", p + "inter"));
      set(out, "channel", rtsp_channel_name(stream, v.rtsp_mount));
      add_chain(bin, {q, visualizer(p + "viz", v.max_flow), make("videoconvert", p + "convert"), out});
      return q;
    }
    case VideoSink::Target::udp: {
      GstElement* q = leaky_queue(p + "queue");
      GstElement* pay = make("rtph264pay", p + "pay");
      set(pay, "config-interval", "1");
      set(pay, "pt", "96");
      GstElement* out = make("udpsink", p + "udp");
      set(out, "host", v.udp_host);
      set(out, "port", std::to_string(v.udp_port));
      set(out, "sync", "false");
      set(out, "async", "false");
      add_chain(bin, {q, visualizer(p + "viz", v.max_flow), make("videoconvert", p + "convert"),
                      h264_encoder(p + "x264", v.bitrate_kbps, true), pay, out});
      return q;
    }
  }
  throw std::logic_error("unknown video sink target");
}

const char* sink_kind(const SinkConfig& sink) {
  switch (sink.settings.index()) {
    case 0: return "files";
    case 1: return "shm";
    case 2: return "video";
    default: return "display";
  }
}

GstPadProbeReturn drop_when_failed(GstPad*, GstPadProbeInfo*, gpointer user_data) {
  const auto* branch = static_cast<const SinkBranch*>(user_data);
  return branch->failed.load(std::memory_order_acquire) ? GST_PAD_PROBE_DROP : GST_PAD_PROBE_OK;
}

}  // namespace

StreamGraph::~StreamGraph() {
  if (pipeline_) gst_element_set_state(pipeline_, GST_STATE_NULL);
  for (auto& b : sinks_) {
    if (b->tee_pad) {
      if (!b->removed && tee_) gst_element_release_request_pad(tee_, b->tee_pad);
      gst_object_unref(b->tee_pad);
    }
    if (b->bin) {
      if (b->removed) gst_element_set_state(b->bin, GST_STATE_NULL);
      gst_object_unref(b->bin);
    }
  }
  if (pipeline_) gst_object_unref(pipeline_);
}

SinkBranch* StreamGraph::branch_of(GstObject* element) {
  for (GstObject* o = element ? GST_OBJECT(gst_object_ref(element)) : nullptr; o;) {
    for (auto& b : sinks_) {
      if (o == GST_OBJECT(b->bin)) {
        gst_object_unref(o);
        return b.get();
      }
    }
    GstObject* parent = gst_object_get_parent(o);
    gst_object_unref(o);
    o = parent;
  }
  return nullptr;
}

size_t StreamGraph::live_branches() const {
  return static_cast<size_t>(std::count_if(sinks_.begin(), sinks_.end(), [](const auto& b) {
    return !b->failed.load(std::memory_order_acquire);
  }));
}

void StreamGraph::remove_branch(SinkBranch& branch) {
  if (branch.removed) return;
  branch.failed.store(true, std::memory_order_release);
  GstPad* sink_pad = gst_element_get_static_pad(branch.bin, "sink");
  gst_pad_unlink(branch.tee_pad, sink_pad);
  gst_object_unref(sink_pad);
  gst_element_release_request_pad(tee_, branch.tee_pad);
  gst_element_set_state(branch.bin, GST_STATE_NULL);
  // Without the branch the pipeline's EOS no longer waits for the failed sink.
  gst_bin_remove(GST_BIN(pipeline_), branch.bin);
  branch.removed = true;
}

std::string rtsp_channel_name(const std::string& stream, const std::string& mount) {
  return "neuflowd/" + stream + mount;
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
    if (digits.empty() || digits.size() > 9 || !std::all_of(digits.begin(), digits.end(), ::isdigit)) continue;
    next = std::max(next, std::stoi(digits) + 1);
  }
  return next;
}

std::unique_ptr<StreamGraph> build_stream_graph(const StreamConfig& config, int threads, const std::string& instance) {
  auto graph = std::make_unique<StreamGraph>();
  graph->pipeline_ = GST_ELEMENT(gst_object_ref_sink(gst_pipeline_new(instance.c_str())));
  auto* bin = GST_BIN(graph->pipeline_);

  GstElement* convert = make("videoconvert", "convert");
  GstElement* flow = make("neuflow", "flow");
  const FlowConfig& f = config.flow;
  set(flow, "model", f.model.string());
  set(flow, "iters-s16", std::to_string(f.iters_s16));
  set(flow, "iters-s8", std::to_string(f.iters_s8));
  set(flow, "model-width", std::to_string(f.model_width));
  set(flow, "model-height", std::to_string(f.model_height));
  set(flow, "threads", std::to_string(threads));
  set(flow, "behaviour", f.behaviour);
  set(flow, "channel-order", f.channel_order);
  set(flow, "stats-interval", "0");  // the daemon reads the counters itself
  GstElement* tee = make("tee", "tee");
  set(tee, "allow-not-linked", "true");
  gst_bin_add(bin, convert);
  GstElement* feed = add_source(bin, config.source, convert);
  if (feed) link(feed, convert);
  gst_bin_add_many(bin, flow, tee, nullptr);
  link(convert, flow);
  link(flow, tee);
  graph->flow_ = flow;
  graph->tee_ = tee;

  for (const SinkConfig& sink : config.sinks) {
    // A branch is built outside the pipeline, so one that cannot be built (its folder cannot
    // be created, an element is missing) leaves nothing behind and the other sinks still run.
    auto branch = std::make_unique<SinkBranch>();
    branch->name = sink.name;
    branch->kind = sink_kind(sink);
    branch->bin = GST_ELEMENT(gst_object_ref_sink(gst_bin_new(("sink-" + sink.name).c_str())));
    try {
      GstElement* first = fill_branch(GST_BIN(branch->bin), config.name, sink);
      GstPad* first_sink = gst_element_get_static_pad(first, "sink");
      GstPad* ghost = gst_ghost_pad_new("sink", first_sink);
      gst_object_unref(first_sink);
      gst_element_add_pad(branch->bin, ghost);
    } catch (const std::exception& e) {
      gst_object_unref(branch->bin);
      graph->unbuilt_.push_back({sink.name, e.what()});
      continue;
    }
    // The pipeline takes a reference of its own; ours is kept after a failed branch leaves
    // the pipeline, for branch_of().
    gst_bin_add(bin, branch->bin);
    GstPad* ghost = gst_element_get_static_pad(branch->bin, "sink");
    branch->tee_pad = gst_element_request_pad_simple(tee, "src_%u");
    const GstPadLinkReturn linked = gst_pad_link(branch->tee_pad, ghost);
    gst_object_unref(ghost);
    if (linked != GST_PAD_LINK_OK) throw std::runtime_error("cannot link the tee to sink " + sink.name);
    gst_pad_add_probe(branch->tee_pad,
                      static_cast<GstPadProbeType>(GST_PAD_PROBE_TYPE_BUFFER | GST_PAD_PROBE_TYPE_BUFFER_LIST),
                      drop_when_failed, branch.get(), nullptr);
    graph->sinks_.push_back(std::move(branch));
  }
  if (graph->sinks_.empty()) {
    std::string reasons;
    for (const auto& failed : graph->unbuilt_) {
      reasons += (reasons.empty() ? "" : "; ") + std::string("sink ") + failed.name + ": " + failed.reason;
    }
    throw std::runtime_error("no sink could be built (" + reasons + ")");
  }
  return graph;
}

}  // namespace neuflow::daemon
