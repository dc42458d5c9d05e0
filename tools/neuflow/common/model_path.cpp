#include "common/model_path.hpp"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "common/exit_codes.hpp"

namespace neuflow::cli {

std::string resolve_model(const std::string& given, const char* subcommand) {
  if (!given.empty()) return given;
  if (const char* env = std::getenv(kModelEnvironment); env && *env) {
    std::fprintf(stderr, "neuflow %s: model %s (from %s)\n", subcommand, env, kModelEnvironment);
    return env;
  }
  std::error_code ec;
  if (std::filesystem::is_regular_file(kDefaultModel, ec)) {
    std::fprintf(stderr, "neuflow %s: model %s (no --model or %s given)\n", subcommand, kDefaultModel,
                 kModelEnvironment);
    return kDefaultModel;
  }
  throw CommandError(kExitUsage, std::string(subcommand) + ": no model: give --model CKPT, set " + kModelEnvironment +
                                     ", or run `neuflow fetch-model mixed` to put the published weights in " +
                                     kDefaultModel);
}

}  // namespace neuflow::cli
