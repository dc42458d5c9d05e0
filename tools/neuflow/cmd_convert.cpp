// Placeholder: replaced by the real `neuflow convert` subcommand.
#include "commands.hpp"

namespace neuflow::cli {
void register_convert(CLI::App&) {}
}  // namespace neuflow::cli
