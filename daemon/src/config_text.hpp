#pragma once
// The bytes of a config file, checked before toml++ sees them (internal to the config loader).
//
// Debian's toml++ 3.3.0 reaches undefined behaviour on some inputs instead of reporting them:
// a non-ASCII character where it looks for whitespace (outside strings and comments, or after
// the line-ending backslash of a multi-line string: upstream marzer/tomlplusplus #190, #295,
// fixed by PR #305) and control characters in keys (an assert in parse_key, an "assume" in
// release builds). TOML allows neither there, so rejecting them first changes what is
// accepted not at all and turns the undefined behaviour into a normal line:column error.
#include <optional>
#include <string>
#include <string_view>

namespace neuflow::daemon {

struct TextProblem {
  int line = 0;    // 1-based
  int column = 0;  // 1-based, in characters (as toml++ counts them)
  std::string message;
};

// Checks that `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past
// U+10FFFF), holds no control character but tab, CR before LF, and LF, and holds non-ASCII
// characters only inside comments and strings (and not as the first character after the
// line-ending backslash of a multi-line basic string). A leading UTF-8 byte-order mark is
// allowed. Returns the first problem, or nothing.
std::optional<TextProblem> check_config_text(std::string_view text);

}  // namespace neuflow::daemon
