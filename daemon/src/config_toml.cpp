#include "config_toml.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <vector>

namespace neuflow::daemon {
namespace {

std::size_t edit_distance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// The candidate a mistyped word most likely meant: within about a third of its length in
// edits (at least 2), or nothing.
std::string_view closest_match(std::string_view word, std::span<const std::string_view> candidates) {
  std::string_view closest;
  std::size_t best = std::max<std::size_t>(2, word.size() / 3) + 1;
  for (const auto candidate : candidates) {
    const std::size_t d = edit_distance(word, candidate);
    if (d < best) {
      best = d;
      closest = candidate;
    }
  }
  return closest;
}

std::string join(std::span<const std::string_view> words) {
  std::string out;
  for (const auto word : words) {
    if (!out.empty()) out += ", ";
    out += word;
  }
  return out;
}

std::string integer_range(std::int64_t min, std::int64_t max) {
  if (max == std::numeric_limits<std::int64_t>::max()) return "an integer >= " + std::to_string(min);
  return "an integer " + std::to_string(min) + ".." + std::to_string(max);
}

std::string number_range(double min, double max, bool min_exclusive) {
  if (min_exclusive) return "a number > " + format_number(min) + " and <= " + format_number(max);
  return "a number " + format_number(min) + ".." + format_number(max);
}

}  // namespace

SourcePosition position_of(const toml::source_region& region) {
  return {static_cast<int>(region.begin.line), static_cast<int>(region.begin.column)};
}

std::string describe_type(const toml::node& node) {
  switch (node.type()) {
    case toml::node_type::table: return "a table";
    case toml::node_type::array: return "an array";
    case toml::node_type::string: return "a string";
    case toml::node_type::integer: return "an integer";
    case toml::node_type::floating_point: return "a float";
    case toml::node_type::boolean: return "a boolean";
    case toml::node_type::date: return "a date";
    case toml::node_type::time: return "a time";
    case toml::node_type::date_time: return "a date-time";
    case toml::node_type::none: break;
  }
  return "nothing";
}

std::string describe_value(const toml::node& node) {
  if (const auto* s = node.as_string()) {
    std::string text = s->get();
    if (text.size() > 40) text = text.substr(0, 37) + "...";
    return "a string (\"" + text + "\")";
  }
  if (const auto* i = node.as_integer()) return std::to_string(i->get());
  if (const auto* f = node.as_floating_point()) return format_number(f->get());
  if (const auto* b = node.as_boolean()) return b->get() ? "true" : "false";
  return describe_type(node);
}

std::string format_number(double value) {
  // Whole numbers as integers: "1000000", not "1e+06".
  if (std::abs(value) < 1e15 && value == std::floor(value)) return std::to_string(static_cast<std::int64_t>(value));
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

TableReader::TableReader(const toml::table& table, std::string what, Issues& issues)
    : table_(table), what_(std::move(what)), issues_(issues) {}

SourcePosition TableReader::where() const {
  SourcePosition at = position_of(table_.source());
  if (at.line > 0) return at;
  // A table that only exists through dotted keys under it has no header: use its first key.
  for (auto&& [key, value] : table_) {
    const SourcePosition k = position_of(key.source());
    if (k.line > 0 && (at.line == 0 || std::pair(k.line, k.column) < std::pair(at.line, at.column))) at = k;
  }
  return at;
}

const toml::node* TableReader::get(std::string_view key) const { return table_.get(key); }

SourcePosition TableReader::position(std::string_view key) const {
  if (const auto* node = get(key)) {
    const SourcePosition at = position_of(node->source());
    if (at.line > 0) return at;
  }
  return where();
}

void TableReader::allow_only(std::span<const std::string_view> valid) const {
  for (auto&& [key, value] : table_) {
    const std::string_view name = key.str();
    if (std::find(valid.begin(), valid.end(), name) != valid.end()) continue;
    std::string message = "unknown key '" + std::string(name) + "' in " + what_;
    if (const auto closest = closest_match(name, valid); !closest.empty()) {
      message += " (did you mean '" + std::string(closest) + "'?)";
    }
    message += "; valid keys: " + join(valid);
    issues_.add(position_of(key.source()), std::move(message));
  }
}

void TableReader::report(std::string_view key, const std::string& message) const {
  issues_.add(position(key), std::string(key) + ": " + message);
}

void TableReader::report_here(const std::string& message) const { issues_.add(where(), message); }

void TableReader::report_missing(std::string_view key, std::string_view expected) const {
  issues_.add(where(), "missing '" + std::string(key) + "' in " + what_ + ": expected " + std::string(expected));
}

void TableReader::wrong_value(std::string_view key, const toml::node& value, std::string_view expected) const {
  issues_.add(position_of(value.source()),
              std::string(key) + ": expected " + std::string(expected) + ", got " + describe_value(value));
}

std::optional<std::string> TableReader::string(std::string_view key, Need need) const {
  const auto* node = get(key);
  if (!node) {
    if (need == Need::required) report_missing(key, "a string");
    return std::nullopt;
  }
  if (const auto* s = node->as_string()) return s->get();
  wrong_value(key, *node, "a string");
  return std::nullopt;
}

std::optional<std::int64_t> TableReader::integer(std::string_view key, std::int64_t min, std::int64_t max,
                                                 Need need) const {
  const auto* node = get(key);
  if (!node) {
    if (need == Need::required) report_missing(key, integer_range(min, max));
    return std::nullopt;
  }
  const auto* i = node->as_integer();
  if (!i || i->get() < min || i->get() > max) {
    wrong_value(key, *node, integer_range(min, max));
    return std::nullopt;
  }
  return i->get();
}

std::optional<double> TableReader::number(std::string_view key, double min, double max, bool min_exclusive) const {
  const auto* node = get(key);
  if (!node) return std::nullopt;
  std::optional<double> value;
  if (const auto* f = node->as_floating_point()) value = f->get();
  if (const auto* i = node->as_integer()) value = static_cast<double>(i->get());
  // Written so that NaN fails every comparison and is reported.
  const bool in_range = value && (min_exclusive ? *value > min : *value >= min) && *value <= max;
  if (!in_range) {
    wrong_value(key, *node, number_range(min, max, min_exclusive));
    return std::nullopt;
  }
  return value;
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
  const auto* node = get(key);
  if (!node) return std::nullopt;
  if (const auto* b = node->as_boolean()) return b->get();
  wrong_value(key, *node, "true or false");
  return std::nullopt;
}

std::optional<std::string> TableReader::choice(std::string_view key, std::span<const std::string_view> values,
                                               Need need) const {
  std::string expected = "one of ";
  for (std::size_t i = 0; i < values.size(); ++i) {
    if (i > 0) expected += i + 1 == values.size() ? " or " : ", ";
    expected += "\"" + std::string(values[i]) + "\"";
  }
  const auto* node = get(key);
  if (!node) {
    if (need == Need::required) report_missing(key, expected);
    return std::nullopt;
  }
  const auto* s = node->as_string();
  if (!s || std::find(values.begin(), values.end(), s->get()) == values.end()) {
    std::string_view closest;
    if (s) closest = closest_match(s->get(), values);
    if (!closest.empty()) expected += " (did you mean \"" + std::string(closest) + "\"?)";
    wrong_value(key, *node, expected);
    return std::nullopt;
  }
  return s->get();
}

const toml::table* TableReader::table(std::string_view key, Need need, std::string_view expected) const {
  const auto* node = get(key);
  if (!node) {
    if (need == Need::required) report_missing(key, expected);
    return nullptr;
  }
  if (const auto* t = node->as_table()) return t;
  wrong_value(key, *node, "a table");
  return nullptr;
}

const toml::array* TableReader::table_array(std::string_view key, Need need, std::string_view expected) const {
  const auto* node = get(key);
  if (!node) {
    if (need == Need::required) report_missing(key, expected);
    return nullptr;
  }
  const auto* array = node->as_array();
  // An empty array is returned: the caller knows how many it needs.
  if (!array || (!array->empty() && !array->is_array_of_tables())) {
    issues_.add(position_of(node->source()), std::string(key) +
                                                 ": expected an array of tables (each one written [[...]] with double "
                                                 "brackets), got " +
                                                 describe_type(*node));
    return nullptr;
  }
  return array;
}

}  // namespace neuflow::daemon
