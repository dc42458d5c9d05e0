#include "stream.hpp"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <stdexcept>

#include "log.hpp"
#include "neuflow/gst/flow_meta.h"
#include "neuflow/pipeline/graph_plan.hpp"

namespace neuflow::daemon {

namespace {

// A run that kept playing this long has recovered: the next failure starts the backoff over.
constexpr double kRecoveredAfterS = 30.0;
// How long a pipeline may take to reach PLAYING (cameras and RTSP servers can be slow).
constexpr double kStartTimeoutS = 30.0;

double seconds_since(Stream::Clock::time_point t) {
  return std::chrono::duration<double>(Stream::Clock::now() - t).count();
}

std::string describe_source(const SourceConfig& source) {
  if (const auto* v = std::get_if<V4l2Source>(&source.settings)) return "v4l2 " + v->device;
  if (const auto* l = std::get_if<LibcameraSource>(&source.settings)) {
    return "libcamera " + (l->camera.empty() ? std::string("(first camera)") : l->camera);
  }
  if (const auto* u = std::get_if<UriSource>(&source.settings)) return u->uri;
  return "test pattern " + std::get<TestSource>(source.settings).pattern;
}

// Sources whose end means the far side went away rather than that the input is done.
bool ends_are_failures(const SourceConfig& source) {
  if (std::holds_alternative<V4l2Source>(source.settings) || std::holds_alternative<LibcameraSource>(source.settings)) {
    return true;
  }
  if (const auto* u = std::get_if<UriSource>(&source.settings)) return u->uri.rfind("file:", 0) != 0;
  return false;
}

std::string error_text(GstMessage* message) {
  GError* err = nullptr;
  gchar* debug = nullptr;
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    gst_message_parse_error(message, &err, &debug);
  } else {
    gst_message_parse_warning(message, &err, &debug);
  }
  std::string text = std::string(GST_OBJECT_NAME(GST_MESSAGE_SRC(message))) + ": " + (err ? err->message : "?");
  if (debug && log_level() >= LogLevel::debug) text += std::string(" (") + debug + ")";
  if (err) g_error_free(err);
  g_free(debug);
  return text;
}

guint64 uint64_property(GstElement* e, const char* name) {
  guint64 v = 0;
  g_object_get(e, name, &v, nullptr);
  return v;
}

}  // namespace

const char* to_string(StreamState state) {
  switch (state) {
    case StreamState::idle: return "idle";
    case StreamState::starting: return "starting";
    case StreamState::playing: return "playing";
    case StreamState::backoff: return "backoff";
    case StreamState::stopping: return "stopping";
    case StreamState::stopped: return "stopped";
    case StreamState::finished: return "finished";
  }
  return "?";
}

Stream::Stream(StreamConfig config, int threads, DaemonSettings settings, StreamTotals carried)
    : config_(std::move(config)),
      threads_(threads),
      settings_(std::move(settings)),
      backoff_s_(settings_.restart_delay_min),
      base_{carried.frames_in, carried.frames_processed, carried.frames_dropped, carried.flows},
      sink_base_(std::move(carried.sinks)),
      inference_(carried.inference),
      restarts_(carried.restarts) {}

StreamTotals Stream::totals() const {
  const StreamSnapshot s = snapshot();
  StreamTotals t{s.frames_in, s.frames_processed, s.frames_dropped, s.flows, s.restarts, s.inference, {}};
  for (const auto& sink : s.sinks) t.sinks[sink.name] = {sink.flows_written, sink.bytes_written, sink.failures};
  return t;
}

void Stream::count_sink_failure(const std::string& sink) { ++sink_base_[sink].failures; }

// Each flow's inference time, from the meta the neuflow element attaches. The meta's API type
// is looked up by name: the daemon reads the struct (neuflow/gst/flow_meta.h) without linking
// the plugin's library, which the plugin has loaded into this process.
GstPadProbeReturn Stream::on_flow_buffer(GstPad*, GstPadProbeInfo* info, gpointer self) {
  // Registered when the first meta is attached, so not known before the first flow.
  static std::atomic<GType> known{0};
  GType api = known.load(std::memory_order_relaxed);
  if (api == 0) {
    api = g_type_from_name("NeuflowFlowMetaAPI");
    if (api == 0) return GST_PAD_PROBE_OK;
    known.store(api, std::memory_order_relaxed);
  }
  GstBuffer* buffer = GST_PAD_PROBE_INFO_BUFFER(info);
  const auto* meta = buffer ? reinterpret_cast<const NeuflowFlowMeta*>(gst_buffer_get_meta(buffer, api)) : nullptr;
  if (meta && meta->width > 0 && GST_CLOCK_TIME_IS_VALID(meta->inference_time)) {
    static_cast<Stream*>(self)->inference_.record(static_cast<double>(meta->inference_time) / GST_SECOND);
  }
  return GST_PAD_PROBE_OK;
}

Stream::~Stream() {
  if (restart_timer_) g_source_remove(restart_timer_);
  if (stop_timer_) g_source_remove(stop_timer_);
  teardown();
}

void Stream::enter(StreamState state) {
  state_ = state;
  state_since_ = Clock::now();
}

void Stream::start() {
  restart_timer_ = 0;
  ++run_;
  const std::string instance = config_.name + (run_ > 1 ? "#" + std::to_string(run_) : "");
  try {
    graph_ = pipeline::build_stream_graph(graph_description(config_, threads_), instance);
  } catch (const std::exception& e) {
    graph_.reset();
    fail(std::string("cannot build the pipeline: ") + e.what());
    return;
  }
  for (const UnbuiltSink& sink : graph_->unbuilt_sinks()) {
    count_sink_failure(sink.name);
    log_error("stream " + config_.name + ": sink " + sink.name + " cannot be built: " + sink.reason +
              "; the stream goes on with its other sinks (tried again at its next restart or reload)");
  }
  GstBus* bus = gst_element_get_bus(graph_->pipeline());
  gst_bus_set_sync_handler(bus, &Stream::on_bus_sync, graph_.get(), nullptr);
  bus_watch_ = gst_bus_add_watch(bus, &Stream::on_bus_message, this);
  gst_object_unref(bus);

  if (GstPad* src = gst_element_get_static_pad(graph_->flow_element(), "src")) {
    gst_pad_add_probe(src, GST_PAD_PROBE_TYPE_BUFFER, &Stream::on_flow_buffer, this, nullptr);
    gst_object_unref(src);
  }

  current_ = {};
  sink_written_now_.clear();
  last_processed_ = 0;
  rate_base_ = 0;
  rate_known_ = false;
  last_rate_at_ = last_progress_ = Clock::now();
  enter(StreamState::starting);
  log_info("stream " + config_.name + ": starting (" + describe_source(config_.source) + ", " +
           std::to_string(config_.sinks.size()) + " sink" + (config_.sinks.size() == 1 ? "" : "s") + ", " +
           std::to_string(threads_) + " inference thread" + (threads_ == 1 ? "" : "s") + ")");
  // A sink that cannot even start (say, its directory is not writable) is cut off like one
  // that fails later, as long as another sink remains; anything else fails the stream.
  while (gst_element_set_state(graph_->pipeline(), GST_STATE_PLAYING) == GST_STATE_CHANGE_FAILURE) {
    GstBus* failed_bus = gst_element_get_bus(graph_->pipeline());
    GstMessage* error = gst_bus_pop_filtered(failed_bus, GST_MESSAGE_ERROR);
    gst_object_unref(failed_bus);
    const std::string text = error ? error_text(error) : "the pipeline could not start";
    SinkBranch* branch = error ? graph_->branch_of(GST_MESSAGE_SRC(error)) : nullptr;
    if (error) gst_message_unref(error);
    if (branch && !branch->removed) {
      branch->failed.store(true, std::memory_order_release);
      if (graph_->live_branches() > 0) {
        count_sink_failure(branch->name);
        log_error("stream " + config_.name + ": sink " + branch->name + " failed: " + text +
                  "; the stream goes on with its other sinks");
        gst_element_set_state(graph_->pipeline(), GST_STATE_NULL);
        graph_->remove_branch(*branch);
        continue;
      }
    }
    fail(branch ? "its only sink " + branch->name + " failed: " + text : text);
    return;
  }
}

void Stream::teardown() {
  if (!graph_) return;
  read_counters();
  base_.in += current_.in;
  base_.processed += current_.processed;
  base_.dropped += current_.dropped;
  base_.flows += current_.flows;
  current_ = {};
  for (const auto& [sink, written] : sink_written_now_) {
    sink_base_[sink].flows_written += written.flows_written;
    sink_base_[sink].bytes_written += written.bytes_written;
  }
  sink_written_now_.clear();
  if (bus_watch_) {
    g_source_remove(bus_watch_);
    bus_watch_ = 0;
  }
  gst_element_set_state(graph_->pipeline(), GST_STATE_NULL);
  GstBus* bus = gst_element_get_bus(graph_->pipeline());
  gst_bus_set_sync_handler(bus, nullptr, nullptr, nullptr);
  gst_object_unref(bus);
  graph_.reset();
  rate_fps_ = 0;
}

void Stream::fail(const std::string& reason) {
  if (state_ == StreamState::stopping) {
    log_error("stream " + config_.name + ": " + reason);
    finish_stop();
    return;
  }
  const bool recovered = state_ == StreamState::playing && seconds_since(state_since_) >= kRecoveredAfterS;
  if (recovered) backoff_s_ = settings_.restart_delay_min;
  teardown();
  settled_ = true;
  ++restarts_;
  log_error("stream " + config_.name + ": " + reason + "; restarting in " + std::to_string(backoff_s_).substr(0, 4) +
            " s");
  enter(StreamState::backoff);
  restart_at_ = Clock::now() + std::chrono::milliseconds(static_cast<long>(backoff_s_ * 1000));
  restart_timer_ = g_timeout_add(static_cast<guint>(backoff_s_ * 1000), &Stream::on_restart_timer, this);
  backoff_s_ = std::min(backoff_s_ * 2, settings_.restart_delay_max);
}

gboolean Stream::on_restart_timer(gpointer self) {
  static_cast<Stream*>(self)->start();
  return G_SOURCE_REMOVE;
}

void Stream::stop(std::function<void()> done) {
  stop_done_ = std::move(done);
  if (restart_timer_) {
    g_source_remove(restart_timer_);
    restart_timer_ = 0;
  }
  if (!graph_ || state_ == StreamState::finished || state_ == StreamState::backoff) {
    finish_stop();
    return;
  }
  enter(StreamState::stopping);
  log_info("stream " + config_.name + ": stopping (end of stream sent)");
  gst_element_send_event(graph_->pipeline(), gst_event_new_eos());
  stop_timer_ = g_timeout_add(static_cast<guint>(settings_.stop_timeout * 1000), &Stream::on_stop_timeout, this);
}

gboolean Stream::on_stop_timeout(gpointer self) {
  auto* s = static_cast<Stream*>(self);
  s->stop_timer_ = 0;
  log_warning("stream " + s->config_.name + ": the end of stream did not get through within " +
              std::to_string(static_cast<int>(s->settings_.stop_timeout)) +
              " s; stopping anyway (the last video file may be incomplete)");
  s->finish_stop();
  return G_SOURCE_REMOVE;
}

void Stream::finish_stop() {
  if (stop_timer_) {
    g_source_remove(stop_timer_);
    stop_timer_ = 0;
  }
  teardown();
  enter(StreamState::stopped);
  log_info("stream " + config_.name + ": stopped");
  if (auto done = std::move(stop_done_)) {
    stop_done_ = nullptr;
    done();
  }
}

GstBusSyncReply Stream::on_bus_sync(GstBus*, GstMessage* message, gpointer graph) {
  // Runs in the thread that posted the error, before the failing element returns its flow
  // error upstream: marking the branch here makes the tee drop its data from now on.
  if (GST_MESSAGE_TYPE(message) == GST_MESSAGE_ERROR) {
    auto* g = static_cast<StreamGraph*>(graph);
    if (SinkBranch* branch = g->branch_of(GST_MESSAGE_SRC(message))) {
      branch->failed.store(true, std::memory_order_release);
    }
  }
  return GST_BUS_PASS;
}

gboolean Stream::on_bus_message(GstBus*, GstMessage* message, gpointer self) {
  static_cast<Stream*>(self)->handle_message(message);
  return G_SOURCE_CONTINUE;
}

void Stream::handle_message(GstMessage* message) {
  if (!graph_) return;
  switch (GST_MESSAGE_TYPE(message)) {
    case GST_MESSAGE_ERROR: {
      const std::string text = error_text(message);
      SinkBranch* branch = graph_->branch_of(GST_MESSAGE_SRC(message));
      if (branch && state_ != StreamState::stopping && graph_->live_branches() > 0) {
        if (!branch->removed) {
          count_sink_failure(branch->name);
          log_error("stream " + config_.name + ": sink " + branch->name + " failed: " + text +
                    "; the stream goes on with its other sinks");
          graph_->remove_branch(*branch);
        }
        return;
      }
      if (branch && state_ == StreamState::stopping) {
        log_error("stream " + config_.name + ": sink " + branch->name + " failed while stopping: " + text);
        if (graph_->live_branches() > 0) {
          graph_->remove_branch(*branch);
          return;
        }
      }
      fail(branch ? "its only sink " + branch->name + " failed: " + text : text);
      return;
    }
    case GST_MESSAGE_WARNING: log_warning("stream " + config_.name + ": " + error_text(message)); return;
    case GST_MESSAGE_EOS:
      if (state_ == StreamState::stopping) {
        finish_stop();
      } else if (ends_are_failures(config_.source)) {
        fail("the source ended (" + describe_source(config_.source) + ")");
      } else {
        teardown();
        settled_ = true;
        enter(StreamState::finished);
        log_notice("stream " + config_.name + ": end of input, finished (" + std::to_string(base_.processed) +
                   " frames)");
      }
      return;
    case GST_MESSAGE_STATE_CHANGED: {
      if (GST_MESSAGE_SRC(message) != GST_OBJECT(graph_->pipeline())) return;
      GstState old_state, new_state;
      gst_message_parse_state_changed(message, &old_state, &new_state, nullptr);
      if (new_state == GST_STATE_PLAYING && state_ == StreamState::starting) mark_playing();
      return;
    }
    default: return;
  }
}

void Stream::mark_playing() {
  enter(StreamState::playing);
  settled_ = true;
  last_progress_ = Clock::now();
  std::string where;
  if (graph_) {
    gchar* running_on = nullptr;
    g_object_get(graph_->flow_element(), "running-on", &running_on, nullptr);
    if (running_on && *running_on) where = std::string(" on ") + running_on;
    g_free(running_on);
  }
  log_info("stream " + config_.name + ": playing" + where);
}

void Stream::read_counters() {
  if (!graph_) return;
  GstElement* flow = graph_->flow_element();
  current_.in = uint64_property(flow, "frames-in");
  current_.processed = uint64_property(flow, "frames-processed");
  current_.dropped = uint64_property(flow, "frames-dropped");
  current_.flows = uint64_property(flow, "flows");
  for (const auto& branch : graph_->sinks()) {
    if (branch->writer) {
      sink_written_now_[branch->name] = {uint64_property(branch->writer, "flows-written"),
                                         uint64_property(branch->writer, "bytes-written"), 0};
    }
  }
}

void Stream::tick() {
  if (!graph_) return;
  read_counters();
  const auto now = Clock::now();
  const double dt = std::chrono::duration<double>(now - last_rate_at_).count();
  if (dt >= 1.0) {
    rate_fps_ = static_cast<double>(current_.processed - rate_base_) / dt;
    rate_known_ = true;
    rate_base_ = current_.processed;
    last_rate_at_ = now;
  }
  if (current_.processed != last_processed_) {
    last_processed_ = current_.processed;
    last_progress_ = now;
  }
  if (const std::uint64_t flows = base_.flows + current_.flows; flows != last_flows_) {
    last_flows_ = flows;
    last_flow_at_ = std::chrono::system_clock::now();
  }
  // Frames leaving the flow element mean the stream runs, even while a sink is still waiting
  // for its first buffer (an H.264 encoder's lookahead holds back the pipeline's PLAYING).
  if (state_ == StreamState::starting && current_.processed > 0) mark_playing();
  if (state_ == StreamState::playing && seconds_since(last_progress_) > settings_.stall_timeout) {
    fail("no frames for " + std::to_string(static_cast<int>(settings_.stall_timeout)) + " s");
  } else if (state_ == StreamState::starting &&
             seconds_since(state_since_) > std::max(kStartTimeoutS, settings_.stall_timeout)) {
    fail("did not start within " + std::to_string(static_cast<int>(std::max(kStartTimeoutS, settings_.stall_timeout))) +
         " s");
  }
}

bool Stream::healthy() const {
  // Every other state is bounded by a timer of ours; a stop that outlives its own timeout by
  // far means the main loop or GStreamer is stuck.
  return !(state_ == StreamState::stopping && seconds_since(state_since_) > settings_.stop_timeout + 10);
}

double Stream::seconds_until_restart() const {
  return std::max(0.0, std::chrono::duration<double>(restart_at_ - Clock::now()).count());
}

StreamSnapshot Stream::snapshot() const {
  StreamSnapshot s;
  s.name = config_.name;
  s.state = state_;
  s.frames_in = base_.in + current_.in;
  s.frames_processed = base_.processed + current_.processed;
  s.frames_dropped = base_.dropped + current_.dropped;
  s.flows = base_.flows + current_.flows;
  s.restarts = restarts_;
  s.inference = inference_.counts();
  for (const SinkConfig& sink : config_.sinks) {
    StreamSnapshot::Sink out;
    out.name = sink.name;
    out.kind = std::string(pipeline::sink_kind(sink.settings));
    out.counts_flows =
        std::holds_alternative<FilesSink>(sink.settings) || std::holds_alternative<ShmSink>(sink.settings);
    const auto base = sink_base_.find(sink.name);
    if (base != sink_base_.end()) {
      out.flows_written = base->second.flows_written;
      out.bytes_written = base->second.bytes_written;
      out.failures = base->second.failures;
    }
    if (const auto now = sink_written_now_.find(sink.name); now != sink_written_now_.end()) {
      out.flows_written += now->second.flows_written;
      out.bytes_written += now->second.bytes_written;
    }
    s.sinks.push_back(std::move(out));
  }
  s.seconds_in_state = seconds_since(state_since_);
  s.seconds_since_progress = seconds_since(last_progress_);
  if (last_flows_ > 0) {
    s.last_flow_unix_s = std::chrono::duration<double>(last_flow_at_.time_since_epoch()).count();
  }
  if (state_ == StreamState::backoff) {
    s.retry_in_s = seconds_until_restart();
  }
  return s;
}

std::string Stream::status() const {
  char buf[160];
  switch (state_) {
    case StreamState::playing:
      // No rate before one has been measured: "0.0 fps" would be a figure nobody measured.
      if (rate_known_) {
        std::snprintf(buf, sizeof buf, "%s %.1f fps", config_.name.c_str(), rate_fps_);
      } else {
        std::snprintf(buf, sizeof buf, "%s playing", config_.name.c_str());
      }
      break;
    case StreamState::backoff:
      std::snprintf(buf, sizeof buf, "%s retry in %.0f s", config_.name.c_str(), seconds_until_restart());
      break;
    default: std::snprintf(buf, sizeof buf, "%s %s", config_.name.c_str(), to_string(state_));
  }
  return buf;
}

}  // namespace neuflow::daemon
