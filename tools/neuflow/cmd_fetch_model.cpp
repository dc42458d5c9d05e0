// Placeholder: replaced by the real `neuflow fetch_model` subcommand.
#include "commands.hpp"

namespace neuflow::cli {
void register_fetch_model(CLI::App&) {}
}  // namespace neuflow::cli
