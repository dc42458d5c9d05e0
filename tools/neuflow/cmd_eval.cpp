// Placeholder: replaced by the real `neuflow eval` subcommand.
#include "commands.hpp"

namespace neuflow::cli {
void register_eval(CLI::App&) {}
}  // namespace neuflow::cli
