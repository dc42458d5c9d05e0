#pragma once
// Locating ../shared/fixtures for tests, and skipping (or, under CI, failing) when absent.
#include <gtest/gtest.h>
#include <filesystem>
#include <optional>
#include <string>

namespace neuflow::test {

// The shared fixtures folder: $NEUFLOW_SHARED_DIR/fixtures if the variable is set, else
// <source>/../shared/fixtures. Empty when that folder does not exist.
std::optional<std::filesystem::path> fixtures_dir();

// True when NEUFLOW_REQUIRE_FIXTURES is set to a non-empty value other than 0.
bool fixtures_required();

// A message naming where fixtures were looked for and how to point the tests at them.
std::string missing_fixtures_message(const std::string& what);

}  // namespace neuflow::test

// Resolves `var` to fixtures_dir()/relative, or skips the test (fails it under CI) when the
// file or folder is absent.
#define NEUFLOW_REQUIRE_FIXTURE(var, relative)                                 \
  std::filesystem::path var;                                                   \
  do {                                                                         \
    auto neuflow_dir_ = ::neuflow::test::fixtures_dir();                       \
    if (neuflow_dir_ && std::filesystem::exists(*neuflow_dir_ / (relative))) { \
      var = *neuflow_dir_ / (relative);                                        \
    } else if (::neuflow::test::fixtures_required()) {                         \
      FAIL() << ::neuflow::test::missing_fixtures_message(relative);           \
    } else {                                                                   \
      GTEST_SKIP() << ::neuflow::test::missing_fixtures_message(relative);     \
    }                                                                          \
  } while (0)
