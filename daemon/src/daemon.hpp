#pragma once
// The daemon: owns the streams, the RTSP server and the metrics endpoint, and talks to the
// service manager. Runs a GLib main loop on the calling thread until SIGTERM/SIGINT (EOS to
// every stream, bounded wait, exit 0) or until every stream has finished its input; SIGHUP
// re-reads the config and restarts only the streams whose settings changed.
#include <glib.h>

#include <chrono>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "notifier.hpp"
#include "stream.hpp"

namespace neuflow::daemon {

class MetricsServer;
class RtspServer;

class Daemon {
 public:
  // `log_level_override`: --log-level, kept over reloads; empty: the config's.
  explicit Daemon(Config config, std::string log_level_override = {});
  ~Daemon();
  Daemon(const Daemon&) = delete;
  Daemon& operator=(const Daemon&) = delete;

  // Runs until stopped; returns the process exit code.
  int run();

 private:
  static gboolean on_terminate(gpointer self);
  static gboolean on_hangup(gpointer self);
  static gboolean on_tick(gpointer self);
  static gboolean on_watchdog(gpointer self);

  // Start, or move from the running config to this one; returns what changed, e.g.
  // "1 stream restarted, 2 unchanged" or "nothing changed".
  std::string apply(Config config);
  void reload();
  void shutdown();
  void start_stream(const StreamConfig& config);
  void retire(std::unique_ptr<Stream> stream, std::function<void()> then = {});
  void update_servers();
  int threads_for(const StreamConfig& stream) const;
  std::string status_line() const;
  std::string render_metrics();

  Config config_;
  std::string log_level_override_;
  GMainLoop* loop_ = nullptr;
  Notifier notifier_;
  std::map<std::string, std::unique_ptr<Stream>> streams_;
  std::vector<std::unique_ptr<Stream>> retiring_;  // stopping after a reload removed or changed them
  std::map<std::string, StreamTotals> totals_;     // of retired streams, by name, for their successors
  std::unique_ptr<RtspServer> rtsp_;
  std::unique_ptr<MetricsServer> metrics_;
  std::optional<MetricsSettings> metrics_settings_;  // what metrics_ listens on
  std::vector<guint> sources_;
  std::chrono::steady_clock::time_point started_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_tick_ = std::chrono::steady_clock::now();
  bool ready_sent_ = false;
  bool reload_pending_ready_ = false;
  bool stopping_ = false;
  size_t stopping_left_ = 0;
};

}  // namespace neuflow::daemon
