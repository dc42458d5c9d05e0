#include "common/usage_errors.hpp"

#include <cstdio>
#include <optional>
#include <string>

#include "common/exit_codes.hpp"

namespace neuflow::cli {

namespace {

// The subcommand the command line chose, or the app itself.
CLI::App* chosen_command(CLI::App& app) {
  CLI::App* command = &app;
  for (bool deeper = true; deeper;) {
    deeper = false;
    for (CLI::App* sub : command->get_subcommands()) {
      if (!sub->get_name().empty()) {
        command = sub;
        deeper = true;
        break;
      }
    }
  }
  return command;
}

bool known_to(const CLI::App* command, const std::string& name) {
  for (; command != nullptr; command = command->get_parent()) {
    if (command->get_option_no_throw(name) != nullptr) return true;
  }
  return false;
}

// The first "--name" / "-x" on the command line that the chosen command does not know.
std::optional<std::string> first_unknown_option(CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* command = chosen_command(app);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--") break;
    if (arg.size() < 2 || arg[0] != '-' || (arg[1] >= '0' && arg[1] <= '9') || arg[1] == '.') continue;
    const std::string name = arg[1] == '-' ? arg.substr(0, arg.find('=')) : arg.substr(0, 2);
    if (!known_to(command, name)) return arg;
  }
  return std::nullopt;
}

}  // namespace

int report_parse_error(CLI::App& app, const CLI::ParseError& error, int argc, const char* const* argv) {
  if (error.get_exit_code() == static_cast<int>(CLI::ExitCodes::Success)) return app.exit(error);  // --help, --version
  // An unknown option is the mistake to name, before what it left missing or extra.
  if (dynamic_cast<const CLI::RequiredError*>(&error) != nullptr || dynamic_cast<const CLI::ExtrasError*>(&error)) {
    if (const auto unknown = first_unknown_option(app, argc, argv)) {
      app.exit(CLI::ExtrasError(std::vector<std::string>{*unknown}));
      return kExitUsage;
    }
  }
  app.exit(error);
  return kExitUsage;
}

int report_no_arguments(CLI::App& app) {
  std::fputs(app.help().c_str(), stderr);
  return kExitUsage;
}

}  // namespace neuflow::cli
