#pragma once
// Helpers for the neuflowd config tests: the issues a config text gives, and a matcher that
// finds one by position and wording.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "config.hpp"

namespace neuflow::daemon::test {

inline const std::filesystem::path kConfigFile = "/etc/neuflow/test.toml";

// Every issue parse_config reports (empty when the config is accepted).
inline std::vector<ConfigIssue> issues_of(const std::string& text, ConfigChecks checks = ConfigChecks::file_only,
                                          const std::filesystem::path& file = kConfigFile) {
  try {
    parse_config(text, file, checks);
  } catch (const ConfigError& error) {
    return error.issues();
  }
  return {};
}

inline std::string listed(const std::vector<ConfigIssue>& issues) {
  std::string text;
  for (const auto& issue : issues) text += "\n  " + issue.to_string();
  return text.empty() ? "\n  (none)" : text;
}

// Passes when one issue is at `line` (and `column`, unless 0) and its message contains `words`.
inline ::testing::AssertionResult has_issue(const std::vector<ConfigIssue>& issues, int line, int column,
                                            const std::string& words) {
  for (const auto& issue : issues) {
    if (issue.line == line && (column == 0 || issue.column == column) &&
        issue.message.find(words) != std::string::npos) {
      return ::testing::AssertionSuccess();
    }
  }
  return ::testing::AssertionFailure() << "no issue at " << line << ":" << column << " containing \"" << words
                                       << "\"; the issues were:" << listed(issues);
}

// A fresh folder under the system's temporary folder, removed with everything in it.
class TempFolder {
 public:
  TempFolder() {
    std::string pattern = (std::filesystem::temp_directory_path() / "neuflowd-config-XXXXXX").string();
    if (!mkdtemp(pattern.data())) throw std::runtime_error("mkdtemp failed for " + pattern);
    path_ = pattern;
  }
  ~TempFolder() {
    std::error_code ec;
    // Folders a test made unwritable must be writable again to be emptied.
    for (auto it = std::filesystem::recursive_directory_iterator(path_, ec);
         !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
      std::filesystem::permissions(it->path(), std::filesystem::perms::owner_all, std::filesystem::perm_options::add,
                                   ec);
    }
    std::filesystem::remove_all(path_, ec);
  }
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;

  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

}  // namespace neuflow::daemon::test
