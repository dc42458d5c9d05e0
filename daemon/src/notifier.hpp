#pragma once
// The service manager's side channel (sd_notify): READY=1, RELOADING=1, STOPPING=1, STATUS=,
// WATCHDOG=1. Without NOTIFY_SOCKET (not run by systemd) every call is a no-op.
#include <chrono>
#include <optional>
#include <string>

namespace neuflow::daemon {

class Notifier {
 public:
  Notifier();

  bool enabled() const { return enabled_; }
  // How often to send WATCHDOG=1 (half of WatchdogSec); nothing when the watchdog is off.
  std::optional<std::chrono::milliseconds> watchdog_interval() const { return watchdog_interval_; }

  void ready(const std::string& status);
  void reloading(const std::string& status);
  void stopping(const std::string& status);
  void status(const std::string& status);
  void watchdog();

 private:
  void send(const std::string& state);
  bool enabled_ = false;
  std::optional<std::chrono::milliseconds> watchdog_interval_;
  std::string last_status_;
};

}  // namespace neuflow::daemon
