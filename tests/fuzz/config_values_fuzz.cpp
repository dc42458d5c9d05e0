// neuflowd's value readers beyond the TOML parse (daemon/src/config_values.hpp): names, host and
// port, shared-memory names and modes, RTSP mounts, file-name patterns, fractions. Each returns
// a problem or a value; none may throw or crash, and what they accept keeps their promises.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>
#include <string_view>

#include "config_values.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  namespace d = neuflow::daemon;
  try {
    (void)d::check_name(text);
    (void)d::check_shm_name(text);
    (void)d::check_rtsp_mount(text);
    std::string error;
    if (const auto hp = d::parse_host_port(text, error); hp && !error.empty()) {
      neuflow::fuzz::invariant_failed("config_values", "a host and port with an error: " + error);
    }
    if (const auto mode = d::parse_octal_mode(text)) (void)d::check_shm_mode(*mode);
    int numerator = 0, denominator = 0;
    if (d::parse_fraction(text, numerator, denominator) && denominator == 0) {
      neuflow::fuzz::invariant_failed("config_values", "a fraction accepted with denominator 0");
    }
    // An accepted pattern gives names at most its own length plus an index's digits.
    if (d::check_index_pattern(text).empty() && text.find('\0') == std::string_view::npos) {
      const std::string pattern(text);
      char name[4096];
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"  // the pattern is what is being checked
      const int n = std::snprintf(name, sizeof name, pattern.c_str(), 2147483647);
#pragma GCC diagnostic pop
      if (n < 0 || static_cast<std::size_t>(n) > pattern.size() + d::kMaxIndexWidth + 1) {
        neuflow::fuzz::invariant_failed(
            "config_values", "pattern '" + pattern + "' gives a name of " + std::to_string(n) + " characters");
      }
    }
  } catch (...) {
    neuflow::fuzz::unexpected_exception("config_values");
  }
  return 0;
}
