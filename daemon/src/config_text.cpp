#include "config_text.hpp"

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <vector>

namespace neuflow::daemon {
namespace {

// Decodes the UTF-8 sequence at text[i]; returns its length, 0 when it is malformed.
std::size_t decode_utf8(std::string_view text, std::size_t i, char32_t& out) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[k]); };
  const unsigned char b0 = byte(i);
  if (b0 < 0x80) {
    out = b0;
    return 1;
  }
  std::size_t length;
  char32_t min;
  if ((b0 & 0xE0) == 0xC0) {
    length = 2, min = 0x80, out = b0 & 0x1F;
  } else if ((b0 & 0xF0) == 0xE0) {
    length = 3, min = 0x800, out = b0 & 0x0F;
  } else if ((b0 & 0xF8) == 0xF0) {
    length = 4, min = 0x10000, out = b0 & 0x07;
  } else {
    return 0;
  }
  if (i + length > text.size()) return 0;
  for (std::size_t k = 1; k < length; ++k) {
    if ((byte(i + k) & 0xC0) != 0x80) return 0;
    out = (out << 6) | (byte(i + k) & 0x3F);
  }
  if (out < min || out > 0x10FFFF || (out >= 0xD800 && out <= 0xDFFF)) return 0;
  return length;
}

std::string hex_bytes(std::string_view text, std::size_t i, std::size_t count) {
  std::string out;
  for (std::size_t k = i; k < text.size() && k < i + count; ++k) {
    char buffer[8];
    std::snprintf(buffer, sizeof buffer, "\\x%02x", static_cast<unsigned char>(text[k]));
    out += buffer;
  }
  return out;
}

std::string code_point(char32_t c) {
  char buffer[16];
  std::snprintf(buffer, sizeof buffer, "U+%04X", static_cast<unsigned>(c));
  return buffer;
}

// Where the scanner is, as far as the rules about non-ASCII characters go.
enum class Context {
  code,               // keys, values, whitespace: ASCII only
  comment,            // to the end of the line
  basic_string,       // "..."
  literal_string,     // '...'
  multiline_basic,    // """..."""
  multiline_literal,  // '''...'''
};

// Where in a statement the code is, as far as telling strings from other quotes goes.
enum class Part {
  key,     // a key, up to its '=' (also the keys of inline tables)
  header,  // inside a [table] or [[array]] header
  value,   // after '='
};

bool bare_key_character(char32_t c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
}

}  // namespace

std::optional<TextProblem> check_config_text(std::string_view text) {
  int line = 1;
  int column = 1;
  Context context = Context::code;
  // The code's grammar, just enough to know where a quote opens a string (toml++ 3.3.0 scans
  // a value that does not start with a quote as code, so `x = 1.5"é"` holds no string), and to
  // reject what its asserts assume away: a table header that does not start with a key, an
  // array element that starts with '}'.
  Part part = Part::key;
  std::vector<char> open;  // '[' arrays and '{' inline tables of the value being read
  char32_t previous = 0;   // the last code character
  int header_brackets = 0;
  bool statement_start = true;  // nothing but blanks and comments since the last statement
  bool starts_key = true;       // the next code character begins a key
  bool starts_value = false;    // the next code character begins a value
  // After a backslash and blanks in a multi-line basic string (a line-ending backslash), until
  // the next character that is not blank: toml++ 3.3.0 classifies it with its whitespace tables.
  bool continuation = false;
  const auto problem = [&](std::string message) { return TextProblem{line, column, std::move(message)}; };
  const auto starts = [&](std::size_t at, std::string_view s) {
    return text.substr(std::min(at, text.size()), s.size()) == s;
  };
  // An ASCII character that may follow a backslash as the second half of an escape pair.
  const auto escapable = [&](std::size_t at) { return at < text.size() && text[at] >= 0x20 && text[at] < 0x7F; };
  const auto ascii_after = [&](std::size_t at) {
    return at >= text.size() || static_cast<unsigned char>(text[at]) < 0x80;
  };
  // Up to two quotes more may still belong to a multi-line string ("""a""""" ends in a"").
  const auto closing_length = [&](std::size_t at, char quote) {
    std::size_t n = 3;
    while (n < 5 && at + n < text.size() && text[at + n] == quote) ++n;
    return n;
  };
  const auto in_array = [&] { return !open.empty() && open.back() == '['; };
  std::size_t i = starts(0, "\xEF\xBB\xBF") ? 3 : 0;  // a byte-order mark
  while (i < text.size()) {
    char32_t c = 0;
    const std::size_t length = decode_utf8(text, i, c);
    if (length == 0) {
      return problem("the file is not valid UTF-8 (bytes " + hex_bytes(text, i, 4) + "); save it as UTF-8");
    }
    if (c == '\n') {
      // An unterminated single-line string is toml++'s to report, in its words.
      if (context == Context::comment || context == Context::basic_string || context == Context::literal_string) {
        context = Context::code;
      }
      if (context == Context::code && part == Part::header && starts_key) {
        return problem("expected a key after '" + std::string(1, static_cast<char>(previous)) +
                       "' in the table header, found the end of the line");
      }
      if (context == Context::code && open.empty() && part != Part::key) {  // a new statement
        part = Part::key;
        previous = 0;
        header_brackets = 0;
        statement_start = starts_key = true;
        starts_value = false;
      } else if (context == Context::code && open.empty() && part == Part::key && !starts_value) {
        // A key that did not end with '=' is toml++'s to report; the next line starts anew.
        previous = 0;
        statement_start = starts_key = true;
      }
      ++line, ++i;
      column = 1;
      continue;
    }
    if (c == '\r') {
      if (!starts(i + 1, "\n")) return problem("a carriage return (\\r) that is not followed by a line feed");
      ++i;  // counted with its line feed
      continue;
    }
    if ((c < 0x20 && c != '\t') || c == 0x7F) {
      return problem("control character " + code_point(c) +
                     " in the file; only tab, line feed and carriage return + line feed are allowed");
    }
    if (c >= 0x80 && context == Context::code) {
      return problem("non-ASCII character " + code_point(c) +
                     " outside a string or comment; only strings and comments may hold non-ASCII text");
    }
    if (continuation) {
      if (c >= 0x80) {
        return problem("non-ASCII character " + code_point(c) +
                       " right after a backslash and blanks in a multi-line string; begin with an ASCII "
                       "character there or remove the backslash");
      }
      if (c != ' ' && c != '\t') continuation = false;
    }

    std::size_t bytes = length;  // consumed by this step
    int characters = 1;
    switch (context) {
      case Context::code: {
        if (c == ' ' || c == '\t') break;
        const bool key_start = starts_key, value_start = starts_value;
        starts_key = starts_value = false;
        // Before comments: toml++ asserts on a '#' there too.
        if (part == Part::header && key_start && !bare_key_character(c) && c != '"' && c != '\'' &&
            !(c == ']' && previous == '[') && !(c == '[' && header_brackets == 1 && text[i - 1] == '[')) {
          return problem("expected a key after '" + std::string(1, static_cast<char>(previous)) +
                         "' in the table header");
        }
        if (value_start && in_array() && c == '}') {
          return problem("expected a value or ']' in the array, found '}'");
        }
        if (c == '#') {
          context = Context::comment;
          starts_key = key_start, starts_value = value_start;  // a comment does not end the wait
          break;
        }
        if ((c == '"' || c == '\'') && (key_start || value_start)) {
          const char quote = static_cast<char>(c);
          if (starts(i, std::string(3, quote))) {
            context = quote == '"' ? Context::multiline_basic : Context::multiline_literal;
            bytes = 3, characters = 3;
          } else {
            context = quote == '"' ? Context::basic_string : Context::literal_string;
          }
          previous = c;
          break;
        }
        if (statement_start && open.empty() && c == '[') {
          part = Part::header;
          header_brackets = 1;
          starts_key = true;
        } else if (part == Part::header && c == '[' && header_brackets == 1 && key_start && text[i - 1] == '[') {
          header_brackets = 2;
          starts_key = true;
        } else if ((part == Part::key || part == Part::header) && c == '.') {
          starts_key = true;
        } else if (part == Part::key && c == '=') {
          part = Part::value;
          starts_value = true;
        } else if (part == Part::value && value_start && c == '[') {
          open.push_back('[');
          starts_value = true;
        } else if (part == Part::value && value_start && c == '{') {
          open.push_back('{');
          part = Part::key;
          starts_key = true;
        } else if (c == ']' && part == Part::value && in_array()) {
          open.pop_back();
        } else if (c == '}' && !open.empty() && open.back() == '{') {
          open.pop_back();
          part = Part::value;
        } else if (c == ',' && part == Part::value && in_array()) {
          starts_value = true;
        } else if (c == ',' && part == Part::value && !open.empty() && open.back() == '{') {
          part = Part::key;
          starts_key = true;
        }
        statement_start = false;
        previous = c;
        break;
      }
      case Context::comment: break;
      case Context::basic_string:
        if (c == '\\' && !ascii_after(i + 1)) {
          ++column;
          return problem("non-ASCII character after a backslash: not an escape sequence (write \\\\ for a backslash)");
        }
        if (c == '\\' && escapable(i + 1)) {
          bytes = 2, characters = 2;
        } else if (c == '"') {
          context = Context::code;
        }
        break;
      case Context::literal_string:
        if (c == '\'') context = Context::code;
        break;
      case Context::multiline_basic:
        if (c == '\\') {
          std::size_t k = i + 1;
          while (k < text.size() && (text[k] == ' ' || text[k] == '\t')) ++k;
          if (k == text.size() || text[k] == '\n' || text[k] == '\r' || k > i + 1) {
            // toml++ skips the blanks after the backslash (and the line end) and classifies the
            // next character as whitespace or not.
            continuation = true;
          } else if (!ascii_after(i + 1)) {
            ++column;
            return problem(
                "non-ASCII character after a backslash: not an escape sequence (write \\\\ for a backslash)");
          } else if (escapable(i + 1)) {
            bytes = 2, characters = 2;
          }
        } else if (starts(i, R"(""")")) {
          bytes = closing_length(i, '"'), characters = static_cast<int>(bytes);
          context = Context::code;
        }
        break;
      case Context::multiline_literal:
        if (starts(i, "'''")) {
          bytes = closing_length(i, '\''), characters = static_cast<int>(bytes);
          context = Context::code;
        }
        break;
    }
    i += bytes;
    column += characters;
  }
  return std::nullopt;
}

}  // namespace neuflow::daemon
