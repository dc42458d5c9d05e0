#pragma once
// neuflowd's log: one line per event on stderr. Under systemd (JOURNAL_STREAM names our
// stderr, or --log-prefix) each line starts with the syslog priority "<N>" that journald
// turns into the entry's priority; on a terminal it starts with the level's name instead.
#include <string>
#include <string_view>

namespace neuflow::daemon {

enum class LogLevel { error = 3, warning = 4, notice = 5, info = 6, debug = 7 };

// "error", "warning", "notice", "info", "debug" → level; throws std::invalid_argument otherwise.
LogLevel parse_log_level(std::string_view name);

// Messages above `level` are not written.
void set_log_level(LogLevel level);
LogLevel log_level();

// Whether lines carry the "<N>" prefix; decided once from the environment at start, forced by tests.
void set_log_priority_prefix(bool on);
void use_log_prefix_from_environment();

void log(LogLevel level, const std::string& message);
inline void log_error(const std::string& m) { log(LogLevel::error, m); }
inline void log_warning(const std::string& m) { log(LogLevel::warning, m); }
inline void log_notice(const std::string& m) { log(LogLevel::notice, m); }
inline void log_info(const std::string& m) { log(LogLevel::info, m); }
inline void log_debug(const std::string& m) { log(LogLevel::debug, m); }

}  // namespace neuflow::daemon
