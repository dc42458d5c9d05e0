#include "daemon.hpp"

#include <glib-unix.h>

#include <algorithm>
#include <csignal>
#include <thread>

#include "log.hpp"
#include "metrics_server.hpp"
#include "prometheus_text.hpp"
#include "rtsp_credentials.hpp"
#include "rtsp_server.hpp"

namespace neuflow::daemon {

namespace {

constexpr guint kTickMs = 500;

}  // namespace

Daemon::Daemon(Config config, std::string log_level_override)
    : config_(std::move(config)), log_level_override_(std::move(log_level_override)) {
  loop_ = g_main_loop_new(nullptr, FALSE);
}

Daemon::~Daemon() {
  for (guint id : sources_) g_source_remove(id);
  streams_.clear();
  retiring_.clear();
  metrics_.reset();
  rtsp_.reset();
  g_main_loop_unref(loop_);
}

int Daemon::threads_for(const StreamConfig& stream) const {
  if (stream.flow.stage.session.threads > 0) return stream.flow.stage.session.threads;
  const int total = config_.daemon.threads > 0 ? config_.daemon.threads
                                               : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const auto sharing = std::count_if(config_.streams.begin(), config_.streams.end(),
                                     [](const StreamConfig& s) { return s.flow.stage.session.threads == 0; });
  // Each stream's inference runs its own OpenMP team; more threads than cores in total would
  // make the teams fight over them.
  return std::max(1, total / static_cast<int>(std::max<long>(1, sharing)));
}

int Daemon::run() {
  sources_.push_back(g_unix_signal_add(SIGTERM, &Daemon::on_terminate, this));
  sources_.push_back(g_unix_signal_add(SIGINT, &Daemon::on_terminate, this));
  sources_.push_back(g_unix_signal_add(SIGHUP, &Daemon::on_hangup, this));
  sources_.push_back(g_timeout_add(kTickMs, &Daemon::on_tick, this));
  if (auto interval = notifier_.watchdog_interval()) {
    sources_.push_back(
        g_timeout_add(static_cast<guint>(std::max<long>(1, interval->count())), &Daemon::on_watchdog, this));
  }
  log_notice("starting " + std::to_string(config_.streams.size()) + " stream" +
             (config_.streams.size() == 1 ? "" : "s") + " from " + config_.file.string());
  Config initial = config_;
  config_.streams.clear();
  apply(std::move(initial));
  g_main_loop_run(loop_);
  log_notice("stopped");
  return 0;
}

void Daemon::start_stream(const StreamConfig& config) {
  const auto carried = totals_.find(config.name);
  auto stream = std::make_unique<Stream>(config, threads_for(config), config_.daemon,
                                         carried == totals_.end() ? StreamTotals{} : carried->second);
  Stream& s = *stream;
  streams_[config.name] = std::move(stream);
  s.start();
}

void Daemon::retire(std::unique_ptr<Stream> stream, std::function<void()> then) {
  Stream* s = stream.get();
  retiring_.push_back(std::move(stream));
  s->stop([this, s, then = std::move(then)] {
    // Destroyed from an idle callback: stop() may report from inside the stream's own bus
    // handler, which must not delete the stream under itself.
    struct Retired {
      Daemon* daemon;
      Stream* stream;
      std::function<void()> then;
    };
    g_idle_add_full(
        G_PRIORITY_DEFAULT,
        [](gpointer p) -> gboolean {
          auto* r = static_cast<Retired*>(p);
          r->daemon->totals_[r->stream->name()] = r->stream->totals();
          auto& list = r->daemon->retiring_;
          list.erase(std::remove_if(list.begin(), list.end(), [&](const auto& x) { return x.get() == r->stream; }),
                     list.end());
          if (r->then) r->then();
          if (r->daemon->stopping_ && --r->daemon->stopping_left_ == 0) g_main_loop_quit(r->daemon->loop_);
          return G_SOURCE_REMOVE;
        },
        new Retired{this, s, then}, [](gpointer p) { delete static_cast<Retired*>(p); });
  });
}

std::string Daemon::apply(Config next) {
  int unchanged = 0, restarted = 0, removed = 0, added = 0;
  const Config previous = std::move(config_);
  config_ = std::move(next);
  if (!log_level_override_.empty()) config_.daemon.log_level = log_level_override_;
  set_log_level(parse_log_level(config_.daemon.log_level));
  // What this machine lacks now; the streams concerned retry until it is there.
  // The log line says "warning" itself.
  for (const ConfigIssue& warning : config_.warnings) log_warning(warning.where_and_what());

  std::map<std::string, const StreamConfig*> wanted;
  for (const StreamConfig& s : config_.streams) wanted[s.name] = &s;

  // The log level is applied above; every other [daemon] setting shapes the streams.
  DaemonSettings before = previous.daemon, after = config_.daemon;
  before.log_level = after.log_level;
  const bool daemon_settings_changed = !(before == after);
  for (auto it = streams_.begin(); it != streams_.end();) {
    auto w = wanted.find(it->first);
    const bool keep = w != wanted.end() && it->second->config() == *w->second &&
                      it->second->threads() == threads_for(*w->second) && !daemon_settings_changed;
    if (keep) {
      wanted.erase(w);
      ++it;
      ++unchanged;
      continue;
    }
    std::unique_ptr<Stream> old = std::move(it->second);
    it = streams_.erase(it);
    if (w == wanted.end()) {
      log_notice("stream " + old->name() + ": removed from the config");
      retire(std::move(old));
      ++removed;
    } else {
      log_notice("stream " + old->name() + ": settings changed, restarting it");
      ++restarted;
      const StreamConfig changed = *w->second;
      wanted.erase(w);
      // The new pipeline starts once the old one has let go of its camera and files.
      retire(std::move(old), [this, changed] {
        if (!stopping_) start_stream(changed);
      });
    }
  }
  for (const auto& [name, stream] : wanted) {
    start_stream(*stream);
    ++added;
  }
  update_servers();

  std::string outcome;
  const auto part = [&](int n, const char* what) {
    if (n == 0) return;
    outcome += (outcome.empty() ? "" : ", ") + std::to_string(n) + " stream" + (n == 1 ? " " : "s ") + what;
  };
  part(restarted, "restarted");
  part(added, "added");
  part(removed, "removed");
  if (outcome.empty()) return "nothing changed";
  part(unchanged, "unchanged");
  return outcome;
}

void Daemon::update_servers() {
  const auto mounts = rtsp_mounts(config_);
  if (rtsp_ && (!config_.rtsp || !(rtsp_->settings() == *config_.rtsp))) rtsp_.reset();
  if (rtsp_) {
    try {
      rtsp_->reload_credentials();  // a reload is how users are added or removed
    } catch (const RtspCredentialsError& e) {
      log_error(std::string(e.what()) + "; the RTSP users stay as they were");
    }
  }
  if (!rtsp_ && config_.rtsp && !mounts.empty()) {
    try {
      rtsp_ = std::make_unique<RtspServer>(*config_.rtsp);
    } catch (const RtspCredentialsError& e) {
      log_error(std::string(e.what()) + "; no RTSP mount is served until it can be read (fix it and reload)");
    } catch (const std::exception& e) {
      log_error(std::string(e.what()) + "; the streams run without their RTSP mounts");
    }
  }
  if (rtsp_) rtsp_->set_mounts(mounts);

  if (metrics_settings_ != config_.metrics) {
    metrics_.reset();
    metrics_settings_.reset();
  }
  if (!metrics_ && config_.metrics) {
    try {
      metrics_ = std::make_unique<MetricsServer>(config_.metrics->address, config_.metrics->port,
                                                 [this] { return render_metrics(); });
      metrics_settings_ = config_.metrics;
      log_info("metrics: serving " + metrics_->url());
    } catch (const std::exception& e) {
      log_error(std::string(e.what()) + "; running without the metrics endpoint");
    }
  }
}

std::string Daemon::render_metrics() {
  std::vector<StreamMetrics> all;
  for (const auto& [name, stream] : streams_) {
    stream->refresh_counters();
    const StreamSnapshot s = stream->snapshot();
    StreamMetrics m;
    m.stream = s.name;
    // The exposition knows the states a user sees; the transient ones map onto them.
    m.state = s.state == StreamState::idle       ? "starting"
              : s.state == StreamState::stopping ? "stopped"
                                                 : to_string(s.state);
    m.frames_in = s.frames_in;
    m.frames_processed = s.frames_processed;
    m.frames_dropped = s.frames_dropped;
    m.restarts = s.restarts;
    m.inference = s.inference;
    m.flows = s.flows;
    m.uptime_s = s.state == StreamState::playing ? s.seconds_in_state : 0.0;
    m.stalled = s.state == StreamState::playing && s.seconds_since_progress > kUpWindowS;
    m.last_flow_unix_s = s.last_flow_unix_s;
    for (const auto& sink : s.sinks) {
      m.sinks.push_back(
          {sink.name, sink.kind, sink.counts_flows, sink.flows_written, sink.bytes_written, sink.failures});
    }
    all.push_back(std::move(m));
  }
  return render_prometheus(all, std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count(),
                           NEUFLOW_VERSION);
}

std::string Daemon::status_line() const {
  std::string line;
  for (const auto& [name, stream] : streams_) {
    if (!line.empty()) line += ", ";
    line += stream->status();
  }
  return line.empty() ? "no streams" : line;
}

void Daemon::reload() {
  log_notice("reloading " + config_.file.string());
  notifier_.reloading("reloading " + config_.file.string());
  try {
    log_notice("reloaded " + config_.file.string() + ": " + apply(load_config(config_.file)));
  } catch (const ConfigError& e) {
    for (const ConfigIssue& issue : e.issues()) log_error(issue.to_string());
    log_error("the new config has errors; the running streams keep their settings");
  } catch (const std::exception& e) {
    log_error(std::string("reload failed: ") + e.what() + "; the running streams keep their settings");
  }
  reload_pending_ready_ = true;
}

void Daemon::shutdown() {
  if (stopping_) {
    log_warning("second stop request: stopping at once");
    g_main_loop_quit(loop_);
    return;
  }
  stopping_ = true;
  notifier_.stopping("stopping");
  log_notice("stopping: end of stream to " + std::to_string(streams_.size() + retiring_.size()) + " stream(s)");
  std::vector<std::unique_ptr<Stream>> all;
  for (auto& [name, stream] : streams_) all.push_back(std::move(stream));
  streams_.clear();
  stopping_left_ = all.size() + retiring_.size();
  if (stopping_left_ == 0) {
    g_main_loop_quit(loop_);
    return;
  }
  // Streams already retiring after a reload are counted off as they finish, like these.
  for (auto& s : all) retire(std::move(s));
}

gboolean Daemon::on_terminate(gpointer self) {
  static_cast<Daemon*>(self)->shutdown();
  return G_SOURCE_CONTINUE;
}

gboolean Daemon::on_hangup(gpointer self) {
  auto* d = static_cast<Daemon*>(self);
  if (!d->stopping_) d->reload();
  return G_SOURCE_CONTINUE;
}

gboolean Daemon::on_tick(gpointer self) {
  auto* d = static_cast<Daemon*>(self);
  d->last_tick_ = std::chrono::steady_clock::now();
  for (auto& [name, stream] : d->streams_) stream->tick();
  for (auto& stream : d->retiring_) stream->tick();
  if (d->stopping_) return G_SOURCE_CONTINUE;

  // After a reload, READY=1 waits for the changed streams to be replaced and settled too.
  const bool settled = d->retiring_.empty() && std::all_of(d->streams_.begin(), d->streams_.end(),
                                                           [](const auto& kv) { return kv.second->settled(); });
  if (settled && (!d->ready_sent_ || d->reload_pending_ready_)) {
    d->notifier_.ready(d->status_line());
    if (!d->ready_sent_) log_notice("ready: " + d->status_line());
    d->ready_sent_ = true;
    d->reload_pending_ready_ = false;
  } else if (d->ready_sent_) {
    d->notifier_.status(d->status_line());
  }

  const bool all_finished = !d->streams_.empty() && d->retiring_.empty() &&
                            std::all_of(d->streams_.begin(), d->streams_.end(),
                                        [](const auto& kv) { return kv.second->state() == StreamState::finished; });
  if (all_finished) {
    log_notice("every stream has finished its input; exiting");
    d->shutdown();
  }
  return G_SOURCE_CONTINUE;
}

gboolean Daemon::on_watchdog(gpointer self) {
  auto* d = static_cast<Daemon*>(self);
  // The main loop answered (we are in it), its tick ran lately, and no stream is stuck in a
  // state change: only then tell systemd all is well.
  const bool ticking = std::chrono::steady_clock::now() - d->last_tick_ < std::chrono::seconds(5);
  const bool streams_ok =
      std::all_of(d->streams_.begin(), d->streams_.end(), [](const auto& kv) { return kv.second->healthy(); }) &&
      std::all_of(d->retiring_.begin(), d->retiring_.end(), [](const auto& s) { return s->healthy(); });
  if (ticking && streams_ok) {
    d->notifier_.watchdog();
  } else {
    log_warning("watchdog: withholding WATCHDOG=1 (main loop or a stream is stuck)");
  }
  return G_SOURCE_CONTINUE;
}

}  // namespace neuflow::daemon
