#include "earlier_files.hpp"

#include <glib.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <optional>
#include <string_view>
#include <system_error>

namespace neuflow::gst {
namespace {

namespace fs = std::filesystem;

// A file-name pattern split around its one integer conversion.
struct NamePattern {
  std::string pattern;  // as given (printf-style, %% for a percent sign)
  std::string prefix;
  std::string suffix;
  int base = 10;
};

std::string unescape_percent(std::string_view text) {
  std::string out;
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '%' && i + 1 < text.size() && text[i + 1] == '%') ++i;
  }
  return out;
}

std::optional<NamePattern> split(const std::string& name) {
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (name[i] != '%') continue;
    if (i + 1 < name.size() && name[i + 1] == '%') {
      ++i;
      continue;
    }
    std::size_t k = i + 1;
    while (k < name.size() && std::string_view("-+ #0.0123456789").find(name[k]) != std::string_view::npos) ++k;
    if (k == name.size()) return std::nullopt;
    NamePattern p;
    switch (name[k]) {
      case 'd':
      case 'i':
      case 'u': p.base = 10; break;
      case 'x':
      case 'X': p.base = 16; break;
      case 'o': p.base = 8; break;
      default: return std::nullopt;
    }
    p.pattern = name;
    p.prefix = unescape_percent(std::string_view(name).substr(0, i));
    p.suffix = unescape_percent(std::string_view(name).substr(k + 1));
    return p;
  }
  return std::nullopt;
}

bool is_digit_in(char c, int base) {
  if (c >= '0' && c <= '9') return c - '0' < base;
  if (base == 16) return (c >= 'a' && c <= 'f') || (c >= 'A' && c <= 'F');
  return false;
}

// The index in `name`, when the pattern produces exactly this name for it: the sink's indices
// are ints from 0, so digits only (no sign), and formatting the index again must give the name
// back (the same width and padding): "flow_7.flo" is not what "flow_%08d.flo" writes.
std::optional<std::int64_t> index_in(const std::string& name, const NamePattern& p) {
  if (name.size() <= p.prefix.size() + p.suffix.size()) return std::nullopt;
  if (name.compare(0, p.prefix.size(), p.prefix) != 0) return std::nullopt;
  if (name.compare(name.size() - p.suffix.size(), p.suffix.size(), p.suffix) != 0) return std::nullopt;
  const std::string digits = name.substr(p.prefix.size(), name.size() - p.prefix.size() - p.suffix.size());
  // An int has at most 11 digits in base 8; longer is not a number this sink wrote.
  if (digits.size() > 11 ||
      !std::all_of(digits.begin(), digits.end(), [&](char c) { return is_digit_in(c, p.base); })) {
    return std::nullopt;
  }
  const long long index = std::stoll(digits, nullptr, p.base);
  if (index > std::numeric_limits<int>::max()) return std::nullopt;
  if (format_index_name(p.pattern, static_cast<int>(index)) != name) return std::nullopt;
  return index;
}

// "flow_00001.flo" from ".flow_00001.flo.tmp-0123abcd", or nothing.
std::optional<std::string> temporary_target(const std::string& name) {
  constexpr std::string_view tag = ".tmp-";
  if (name.size() < 1 + tag.size() + 8 + 1 || name[0] != '.') return std::nullopt;
  const std::string hex = name.substr(name.size() - 8);
  if (!std::all_of(hex.begin(), hex.end(), [](char c) { return is_digit_in(c, 16); })) return std::nullopt;
  if (name.compare(name.size() - 8 - tag.size(), tag.size(), tag) != 0) return std::nullopt;
  return name.substr(1, name.size() - 1 - tag.size() - 8);
}

fs::path folder_of(const fs::path& path) { return path.parent_path().empty() ? fs::path(".") : path.parent_path(); }

}  // namespace

std::string format_index_name(const std::string& pattern, int index) {
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wformat-nonliteral"
  gchar* name = g_strdup_printf(pattern.c_str(), index);
#pragma GCC diagnostic pop
  std::string out(name);
  g_free(name);
  return out;
}

std::vector<EarlierFile> files_matching(const std::string& pattern) {
  const fs::path path(pattern);
  const auto p = split(path.filename().string());
  std::vector<EarlierFile> found;
  if (!p) return found;
  std::error_code ec;
  for (fs::directory_iterator it(folder_of(path), ec), end; !ec && it != end; it.increment(ec)) {
    const auto index = index_in(it->path().filename().string(), *p);
    if (!index) continue;
    std::error_code size_error;
    if (!it->is_regular_file(size_error)) continue;
    const auto bytes = it->file_size(size_error);
    found.push_back({it->path().string(), *index, size_error ? 0 : static_cast<std::uint64_t>(bytes)});
  }
  std::sort(found.begin(), found.end(), [](const EarlierFile& a, const EarlierFile& b) { return a.index < b.index; });
  return found;
}

std::vector<std::string> remove_stale_temporaries(const std::string& pattern, const std::string& index_path) {
  std::vector<std::string> removed;
  const fs::path path(pattern);
  const auto p = split(path.filename().string());
  const std::string index_name = index_path.empty() ? std::string() : fs::path(index_path).filename().string();
  const auto sweep = [&](const fs::path& folder, auto&& wanted) {
    std::error_code ec;
    for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
      const auto target = temporary_target(it->path().filename().string());
      if (!target || !wanted(*target)) continue;
      std::error_code remove_error;
      if (fs::remove(it->path(), remove_error)) removed.push_back(it->path().string());
    }
  };
  if (p) sweep(folder_of(path), [&](const std::string& target) { return index_in(target, *p).has_value(); });
  if (!index_name.empty()) {
    sweep(folder_of(fs::path(index_path)), [&](const std::string& target) { return target == index_name; });
  }
  return removed;
}

}  // namespace neuflow::gst
