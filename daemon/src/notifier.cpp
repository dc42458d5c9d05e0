#include "notifier.hpp"

#include <systemd/sd-daemon.h>

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <cstring>

#include "log.hpp"

namespace neuflow::daemon {

Notifier::Notifier() {
  const char* socket = std::getenv("NOTIFY_SOCKET");
  enabled_ = socket != nullptr && *socket != '\0';
  std::uint64_t usec = 0;
  // unset_environment = 0: children (GStreamer helpers) never see these anyway.
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) {
    watchdog_interval_ = std::chrono::milliseconds(usec / 2000);
  }
}

void Notifier::send(const std::string& state) {
  if (!enabled_) return;
  const int r = sd_notify(0, state.c_str());
  if (r < 0) log_warning(std::string("sd_notify failed: ") + std::strerror(-r));
}

void Notifier::ready(const std::string& s) {
  last_status_ = s;
  send("READY=1\nSTATUS=" + s);
}

void Notifier::reloading(const std::string& s) {
  last_status_ = s;
  send("RELOADING=1\nSTATUS=" + s);
}

void Notifier::stopping(const std::string& s) {
  last_status_ = s;
  send("STOPPING=1\nSTATUS=" + s);
}

void Notifier::status(const std::string& s) {
  if (s == last_status_) return;  // STATUS= is refreshed every second; say it only when it changes
  last_status_ = s;
  send("STATUS=" + s);
}

void Notifier::watchdog() { send("WATCHDOG=1"); }

}  // namespace neuflow::daemon
