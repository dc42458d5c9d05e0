// Loading a config: the file → TOML → Config, then what it refers to on this machine. The
// schema lives in config_read*.cpp, the machine checks in config_environment.cpp.
#include "config.hpp"

#include <gst/gst.h>
#include <toml++/toml.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

#include "config_environment.hpp"
#include "config_issues.hpp"
#include "config_read.hpp"
#include "config_text.hpp"
#include "config_toml.hpp"

namespace neuflow::daemon {
namespace {

std::string summary(const std::vector<ConfigIssue>& issues) {
  std::string text;
  for (const auto& issue : issues) {
    if (!text.empty()) text += '\n';
    text += issue.to_string();
  }
  return text;
}

[[noreturn]] void fail(const std::filesystem::path& file, std::string message) {
  throw ConfigError({ConfigIssue{file, 0, 0, std::move(message)}});
}

}  // namespace

namespace {
std::string position_text(const ConfigIssue& issue) {
  std::string text = issue.file.string();
  if (issue.line > 0) {
    text += ':' + std::to_string(issue.line);
    if (issue.column > 0) text += ':' + std::to_string(issue.column);
  }
  return text;
}
}  // namespace

std::string ConfigIssue::to_string() const {
  return position_text(*this) + (is_warning() ? ": warning: " : ": ") + message;
}

std::string ConfigIssue::where_and_what() const { return position_text(*this) + ": " + message; }

std::string ConfigIssue::source_excerpt() const {
  if (line <= 0) return {};
  std::ifstream in(file, std::ios::binary);
  std::string text;
  for (int n = 0; n < line && std::getline(in, text); ++n) {
  }
  if (!in && text.empty()) return {};
  if (!text.empty() && text.back() == '\r') text.pop_back();
  std::string excerpt = "    " + text;
  if (column > 0) {
    // Tabs stay tabs under the text so the caret lines up in any terminal.
    std::string pad;
    for (int i = 0; i + 1 < column && i < static_cast<int>(text.size()); ++i) pad += text[i] == '\t' ? '\t' : ' ';
    excerpt += "\n    " + pad + "^";
  }
  return excerpt;
}

ConfigError::ConfigError(std::vector<ConfigIssue> issues)
    : std::runtime_error(summary(issues)), issues_(std::move(issues)) {}

Config load_config(const std::filesystem::path& file, ConfigChecks checks) {
  std::error_code ec;
  if (std::filesystem::is_directory(file, ec)) fail(file, "is a folder; expected a TOML config file");
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, std::string("cannot open the config file: ") + std::strerror(errno));
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad()) fail(file, std::string("cannot read the config file: ") + std::strerror(errno));
  return parse_config(text.str(), file, checks);
}

Config parse_config(const std::string& text, const std::filesystem::path& file, ConfigChecks checks) {
  if (checks == ConfigChecks::all && !gst_is_initialized()) {
    throw std::logic_error("neuflowd config: call gst_init() before checking a config against this machine");
  }
  Issues issues(file);
  if (const auto problem = check_config_text(text)) {
    issues.add({problem->line, problem->column}, problem->message);
    throw ConfigError(issues.take_sorted());
  }
  toml::table root;
  try {
    root = toml::parse(std::string_view(text), std::string_view(file.string()));
  } catch (const toml::parse_error& error) {
    issues.add(position_of(error.source()), "invalid TOML: " + std::string(error.description()));
    throw ConfigError(issues.take_sorted());
  }
  ReadResult result = read_config(root, file, issues);
  std::vector<ConfigIssue> warnings;
  if (checks == ConfigChecks::all) {
    Issues machine(file);
    check_machine(result.needs, installed_gstreamer(), machine, issues);
    warnings = machine.take_sorted();
    for (auto& warning : warnings) warning.severity = ConfigIssue::Severity::warning;
  }
  if (!issues.empty()) {
    issues.add_all(std::move(warnings));
    throw ConfigError(issues.take_sorted());
  }
  result.config.warnings = std::move(warnings);
  return std::move(result.config);
}

pipeline::GraphDescription graph_description(const StreamConfig& stream, int threads) {
  pipeline::GraphDescription graph;
  graph.name = stream.name;
  graph.source = stream.source.settings;
  graph.flow = stream.flow.stage;
  graph.flow.session.threads = threads;
  for (const SinkConfig& sink : stream.sinks) graph.sinks.push_back({sink.name, sink.settings});
  return graph;
}

}  // namespace neuflow::daemon
