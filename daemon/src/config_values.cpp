#include "config_values.hpp"

#include <array>
#include <charconv>

#include "neuflow/flow_ring.hpp"

namespace neuflow::daemon {
namespace {

bool is_name_char(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

bool parse_int(std::string_view text, int& value) {
  if (text.empty()) return false;
  const auto result = std::from_chars(text.data(), text.data() + text.size(), value);
  return result.ec == std::errc{} && result.ptr == text.data() + text.size();
}

}  // namespace

std::string check_name(std::string_view name) {
  constexpr std::size_t max_length = 64;
  if (name.empty() || name.size() > max_length) return "1 to 64 characters from A-Z a-z 0-9 _ -";
  for (const char c : name) {
    if (!is_name_char(c)) return "only the characters A-Z a-z 0-9 _ - (at most 64)";
  }
  return {};
}

std::optional<HostPort> parse_host_port(std::string_view text, std::string& error) {
  const std::string expected = "\"host:port\" (e.g. \"127.0.0.1:9464\", \"[::1]:9464\")";
  HostPort out;
  std::string_view port;
  if (text.starts_with('[')) {
    const auto close = text.find(']');
    if (close == std::string_view::npos || close + 1 >= text.size() || text[close + 1] != ':') {
      error = expected;
      return std::nullopt;
    }
    out.host = std::string(text.substr(1, close - 1));
    port = text.substr(close + 2);
  } else {
    const auto colon = text.rfind(':');
    if (colon == std::string_view::npos) {
      error = expected + "; the port is missing";
      return std::nullopt;
    }
    out.host = std::string(text.substr(0, colon));
    if (out.host.find(':') != std::string::npos) {
      error = expected + "; write IPv6 addresses in brackets";
      return std::nullopt;
    }
    port = text.substr(colon + 1);
  }
  if (out.host.empty() || out.host.find_first_of(" \t/") != std::string::npos) {
    error = expected + "; the host is missing or malformed";
    return std::nullopt;
  }
  if (!parse_int(port, out.port) || out.port < 1 || out.port > 65535) {
    error = expected + " with a port 1..65535";
    return std::nullopt;
  }
  return out;
}

std::string check_shm_name(std::string_view name) {
  const std::string problem = ring::segment_name_problem(name);
  return problem.empty() ? std::string() : "a name like \"/neuflow-front\" (" + problem + ")";
}

std::string check_shm_mode(unsigned mode) {
  // The ring's own rule (neuflowshmsink refuses anything else at start), in the config's words.
  if (ring::segment_mode_problem(mode).empty()) return {};
  return "an octal mode like \"0640\" (or 0o640) with read/write bits only, at least 0600 and at most 0666";
}

std::optional<unsigned> parse_octal_mode(std::string_view text) {
  if (text.size() < 3 || text.size() > 4) return std::nullopt;
  unsigned mode = 0;
  for (const char c : text) {
    if (c < '0' || c > '7') return std::nullopt;
    mode = mode * 8 + static_cast<unsigned>(c - '0');
  }
  return mode;
}

std::string check_rtsp_mount(std::string_view mount) {
  std::string expected = "a mount point like \"/front\": '/' then A-Z a-z 0-9 . _ - and '/' between parts";
  if (mount.size() < 2 || mount.front() != '/' || mount.back() == '/') return expected;
  if (mount.find("//") != std::string_view::npos) return expected;
  for (const char c : mount) {
    if (!is_name_char(c) && c != '.' && c != '/') return expected;
  }
  return {};
}

std::string check_index_pattern(std::string_view file_name) {
  int conversions = 0;
  for (std::size_t i = 0; i < file_name.size(); ++i) {
    if (file_name[i] != '%') continue;
    if (i + 1 < file_name.size() && file_name[i + 1] == '%') {
      ++i;
      continue;
    }
    std::size_t j = i + 1;
    while (j < file_name.size() && file_name[j] >= '0' && file_name[j] <= '9') ++j;
    if (j >= file_name.size() || file_name[j] != 'd') {
      return "at most one number conversion like %05d (write %% for a literal %)";
    }
    // Wider than an index's digits only pads the name (%99999d: names of 100 kB, which no file
    // system takes).
    const std::string_view width = file_name.substr(i + 1, j - i - 1);  // with its '0' flag, if any
    const std::size_t first = width.find_first_not_of('0');
    const std::string_view value = first == std::string_view::npos ? std::string_view{} : width.substr(first);
    if (value.size() > 2 || (!value.empty() && std::stoi(std::string(value)) > kMaxIndexWidth)) {
      return "a number conversion at most " + std::to_string(kMaxIndexWidth) + " digits wide like %05d, found %" +
             std::string(width) + "d";
    }
    ++conversions;
    i = j;
  }
  if (conversions > 1) return "at most one number conversion like %05d, found " + std::to_string(conversions);
  return {};
}

bool parse_fraction(std::string_view text, int& numerator, int& denominator) {
  const auto slash = text.find('/');
  if (slash == std::string_view::npos) return false;
  return parse_int(text.substr(0, slash), numerator) && parse_int(text.substr(slash + 1), denominator) &&
         numerator > 0 && denominator > 0;
}

std::filesystem::path resolve_path(const std::filesystem::path& folder, const std::string& written) {
  const std::filesystem::path path(written);
  if (path.is_absolute()) return path.lexically_normal();
  return (folder / path).lexically_normal();
}

std::span<const std::string_view> test_patterns() {
  // From gst-inspect-1.0 videotestsrc (1.22); kept here so that --check-config works the same
  // on machines where the plugin is missing (that is reported separately).
  // clang-format off
  static constexpr std::array<std::string_view, 26> patterns = {
      "smpte", "snow", "black", "white", "red", "green", "blue", "checkers-1", "checkers-2", "checkers-4",
      "checkers-8", "circular", "blink", "smpte75", "zone-plate", "gamut", "chroma-zone-plate", "solid-color",
      "ball", "smpte100", "bar", "pinwheel", "spokes", "gradient", "colors", "smpte-rp-219"};
  // clang-format on
  return patterns;
}

}  // namespace neuflow::daemon
