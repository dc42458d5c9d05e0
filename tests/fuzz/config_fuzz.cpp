// neuflowd's config loader on the file alone: parse_config(text, file, ConfigChecks::file_only)
// — the byte screening of config_text.cpp, toml++, and the schema (config_read*.cpp).
// ConfigError is the documented failure (with at least one error among its issues); any other
// exception, a sanitizer report, or one of toml++'s assertions (live in the fuzz build, which
// compiles toml++ itself, instrumented) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>

#include "config.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const auto config =
        neuflow::daemon::parse_config(text, "/fuzz/neuflowd.toml", neuflow::daemon::ConfigChecks::file_only);
    if (config.streams.empty()) neuflow::fuzz::invariant_failed("config", "accepted without a stream");
    for (const auto& stream : config.streams) {
      if (stream.sinks.empty()) {
        neuflow::fuzz::invariant_failed("config", "stream '" + stream.name + "' accepted without a sink");
      }
    }
    if (!config.warnings.empty()) neuflow::fuzz::invariant_failed("config", "machine warnings with file_only");
  } catch (const neuflow::daemon::ConfigError& error) {
    bool has_error = false;
    for (const auto& issue : error.issues()) has_error = has_error || !issue.is_warning();
    if (!has_error)
      neuflow::fuzz::invariant_failed("config", "ConfigError without an error: " + std::string(error.what()));
  } catch (...) {
    neuflow::fuzz::unexpected_exception("config");
  }
  return 0;
}
