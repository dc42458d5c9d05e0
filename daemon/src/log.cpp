#include "log.hpp"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <stdexcept>

namespace neuflow::daemon {

namespace {

std::atomic<LogLevel> g_level{LogLevel::info};
std::atomic<bool> g_prefix{false};
std::mutex g_write_mutex;  // GStreamer's threads log too; keep lines whole

const char* level_name(LogLevel level) {
  switch (level) {
    case LogLevel::error: return "error";
    case LogLevel::warning: return "warning";
    case LogLevel::notice: return "notice";
    case LogLevel::info: return "info";
    case LogLevel::debug: return "debug";
  }
  return "?";
}

// systemd sets JOURNAL_STREAM to "<dev>:<inode>" of the stream it connected to our stderr;
// only when it matches is stderr really the journal (a child shell may inherit the variable).
bool stderr_is_journal() {
  const char* env = std::getenv("JOURNAL_STREAM");
  if (!env) return false;
  unsigned long long dev = 0, ino = 0;
  if (std::sscanf(env, "%llu:%llu", &dev, &ino) != 2) return false;
  struct stat st {};
  if (fstat(STDERR_FILENO, &st) != 0) return false;
  return static_cast<unsigned long long>(st.st_dev) == dev && static_cast<unsigned long long>(st.st_ino) == ino;
}

}  // namespace

LogLevel parse_log_level(std::string_view name) {
  for (LogLevel l : {LogLevel::error, LogLevel::warning, LogLevel::notice, LogLevel::info, LogLevel::debug}) {
    if (name == level_name(l)) return l;
  }
  throw std::invalid_argument("unknown log level '" + std::string(name) +
                              "' (expected error, warning, notice, info or debug)");
}

void set_log_level(LogLevel level) { g_level = level; }
LogLevel log_level() { return g_level; }
void set_log_priority_prefix(bool on) { g_prefix = on; }
void use_log_prefix_from_environment() { g_prefix = stderr_is_journal(); }

void log(LogLevel level, const std::string& message) {
  if (static_cast<int>(level) > static_cast<int>(g_level.load())) return;
  // One line per event: GStreamer's debug strings carry line breaks of their own.
  std::string line = message;
  std::replace(line.begin(), line.end(), '\n', ' ');
  std::lock_guard lock(g_write_mutex);
  if (g_prefix) {
    std::fprintf(stderr, "<%d>%s\n", static_cast<int>(level), line.c_str());
  } else {
    std::fprintf(stderr, "neuflowd: %s: %s\n", level_name(level), line.c_str());
  }
  std::fflush(stderr);
}

}  // namespace neuflow::daemon
