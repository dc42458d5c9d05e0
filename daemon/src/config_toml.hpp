#pragma once
// Checked access to one TOML table, for the config loader (internal). Every read names the key
// and what was expected when a value is missing, of the wrong type or out of range, so the
// schema code only states what it wants; keys a table should not have are reported with the
// valid ones.
#include <toml++/toml.h>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "config_issues.hpp"

namespace neuflow::daemon {

SourcePosition position_of(const toml::source_region& region);

// "a string", "an integer", "a table", ... as a user would say it.
std::string describe_type(const toml::node& node);

// The value as written, for messages: short scalars shown ("a string (\"8\")", "100"), tables
// and arrays by their type.
std::string describe_value(const toml::node& node);

// Shortest decimal form of a number ("0.5", "20", "1000000").
std::string format_number(double value);

class TableReader {
 public:
  enum class Need { optional, required };

  // `what` names the table in messages, e.g. "[stream.flow]".
  TableReader(const toml::table& table, std::string what, Issues& issues);

  const toml::table& table() const { return table_; }
  const std::string& what() const { return what_; }
  Issues& issues() const { return issues_; }

  // The table's header; for tables written inline or with dotted keys, where they start.
  SourcePosition where() const;

  // The value's position, or the table's when the key is absent.
  SourcePosition position(std::string_view key) const;
  const toml::node* get(std::string_view key) const;
  bool has(std::string_view key) const { return get(key) != nullptr; }

  // Reports every key not in `valid`, at the key, listing the valid ones (and the closest one
  // when the key looks like a typo of it).
  void allow_only(std::span<const std::string_view> valid) const;

  // The typed reads return nullopt when the key is absent (reported if `need` is required) or
  // its value is unusable (always reported). Integers and numbers are checked against
  // [min, max]; `number` also takes integers.
  std::optional<std::string> string(std::string_view key, Need need = Need::optional) const;
  std::optional<std::int64_t> integer(std::string_view key, std::int64_t min, std::int64_t max,
                                      Need need = Need::optional) const;
  std::optional<double> number(std::string_view key, double min, double max, bool min_exclusive = false) const;
  std::optional<bool> boolean(std::string_view key) const;
  std::optional<std::string> choice(std::string_view key, std::span<const std::string_view> values,
                                    Need need = Need::optional) const;

  // A sub-table (`[stream.source]`, or `source = { ... }`); nullptr when absent or not a table.
  // `expected` describes it when it is required and missing.
  const toml::table* table(std::string_view key, Need need, std::string_view expected = {}) const;
  // An array of tables (`[[stream.sink]]`), possibly empty; nullptr when absent or not one.
  const toml::array* table_array(std::string_view key, Need need, std::string_view expected = {}) const;

  // "<key>: <message>" at the value (or at the table when the key is absent).
  void report(std::string_view key, const std::string& message) const;
  // "<message>" at the table.
  void report_here(const std::string& message) const;
  // "missing <key> in <table>: <expected>" at the table.
  void report_missing(std::string_view key, std::string_view expected) const;

 private:
  void wrong_value(std::string_view key, const toml::node& value, std::string_view expected) const;

  const toml::table& table_;
  std::string what_;
  Issues& issues_;
};

}  // namespace neuflow::daemon
