#pragma once
// Collects what is wrong with a config file while it is read, so that one run reports every
// problem instead of stopping at the first (internal to the config loader).
#include <algorithm>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "config.hpp"

namespace neuflow::daemon {

class Issues {
 public:
  explicit Issues(std::filesystem::path file) : file_(std::move(file)) {}

  void add(SourcePosition at, std::string message) {
    issues_.push_back(ConfigIssue{file_, at.line, at.column, std::move(message)});
  }
  void add_all(std::vector<ConfigIssue> more) {
    for (auto& issue : more) issues_.push_back(std::move(issue));
  }
  bool empty() const { return issues_.empty(); }
  std::size_t size() const { return issues_.size(); }
  const std::filesystem::path& file() const { return file_; }

  // In the order of the file (tables are iterated by key name, not by position); issues about
  // the file as a whole (line 0) come first.
  std::vector<ConfigIssue> take_sorted() {
    std::stable_sort(issues_.begin(), issues_.end(), [](const ConfigIssue& a, const ConfigIssue& b) {
      return std::pair(a.line, a.column) < std::pair(b.line, b.column);
    });
    return std::move(issues_);
  }

 private:
  std::filesystem::path file_;
  std::vector<ConfigIssue> issues_;
};

}  // namespace neuflow::daemon
