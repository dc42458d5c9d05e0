#pragma once
// The formats of single values in a config file (names, addresses, file name patterns,
// paths), checked without touching the machine (internal to the config loader). The checks
// return an empty string when the value is fine, else what was expected, for the message.
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace neuflow::daemon {

// Stream and sink names: they name GStreamer elements, log lines and metric labels.
std::string check_name(std::string_view name);

struct HostPort {
  std::string host;
  int port = 0;
};
// "host:port", with IPv6 hosts in brackets ("[::1]:5000"); the brackets are not kept.
std::optional<HostPort> parse_host_port(std::string_view text, std::string& error);

// A POSIX shared-memory object name: "/name", no further '/'.
std::string check_shm_name(std::string_view name);

// The permissions of a shared-memory ring: read/write bits only, the owner's included.
std::string check_shm_mode(unsigned mode);
// "0640" / "640" → 0640; nothing when it is not 3 or 4 octal digits.
std::optional<unsigned> parse_octal_mode(std::string_view text);

// An RTSP server mount point: "/front", "/cameras/front".
std::string check_rtsp_mount(std::string_view mount);

// A file name that may hold one printf integer conversion for a running number ("%05d", at
// most kMaxIndexWidth wide); anything else would be handed to printf by the muxer. "%%" is a
// literal '%'.
inline constexpr int kMaxIndexWidth = 10;  // an int's digits
std::string check_index_pattern(std::string_view file_name);

// "30000/1001": both positive.
bool parse_fraction(std::string_view text, int& numerator, int& denominator);

// Relative paths are taken from `folder` (the config file's); the result is normalized.
std::filesystem::path resolve_path(const std::filesystem::path& folder, const std::string& written);

// videotestsrc's pattern nicks (GstVideoTestSrcPattern, GStreamer 1.22).
std::span<const std::string_view> test_patterns();

}  // namespace neuflow::daemon
