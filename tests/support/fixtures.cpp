#include "support/fixtures.hpp"

#include <cstdlib>

namespace neuflow::test {

namespace {
std::filesystem::path shared_dir() {
  if (const char* env = std::getenv("NEUFLOW_SHARED_DIR"); env != nullptr && *env != '\0') {
    return env;
  }
  return NEUFLOW_DEFAULT_SHARED_DIR;
}
}  // namespace

std::optional<std::filesystem::path> fixtures_dir() {
  const auto dir = shared_dir() / "fixtures";
  std::error_code ec;
  if (std::filesystem::is_directory(dir, ec)) return std::filesystem::weakly_canonical(dir, ec);
  return std::nullopt;
}

bool fixtures_required() {
  const char* env = std::getenv("NEUFLOW_REQUIRE_FIXTURES");
  return env != nullptr && *env != '\0' && std::string(env) != "0";
}

std::string missing_fixtures_message(const std::string& what) {
  return "fixture '" + what + "' not found under " + (shared_dir() / "fixtures").string() +
         " (set NEUFLOW_SHARED_DIR to the folder that holds fixtures/; "
         "NEUFLOW_REQUIRE_FIXTURES=1 makes this a failure)";
}

}  // namespace neuflow::test
