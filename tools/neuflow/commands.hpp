#pragma once
// Each subcommand of `neuflow` lives in its own cmd_*.cpp and registers itself on the app
// through one of the functions below; main.cpp calls them all.
#include <CLI/CLI.hpp>

#include "common/exit_codes.hpp"

namespace neuflow::cli {

// Registration functions, one per cmd_*.cpp.
void register_viz(CLI::App& app);
void register_compare(CLI::App& app);
void register_inspect(CLI::App& app);
void register_flow(CLI::App& app);
void register_convert(CLI::App& app);
void register_eval(CLI::App& app);
void register_fetch_model(CLI::App& app);
void register_devices(CLI::App& app);

}  // namespace neuflow::cli
