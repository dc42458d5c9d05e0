#pragma once
// How the command line's mistakes are reported: CLI11's message, then exit 64 (EX_USAGE, like
// the other sysexits codes the tools use) instead of CLI11's own 105, 106, 109...; an unknown
// option is named before a missing required one, since it is usually why the required one
// seems missing (a misspelt --model).
#include <CLI/CLI.hpp>

namespace neuflow::cli {

// The exit code for `error` thrown by app.parse(argc, argv), after printing it: 0 for --help
// and --version, kExitUsage for everything else.
int report_parse_error(CLI::App& app, const CLI::ParseError& error, int argc, const char* const* argv);

// `neuflow` alone: the help on stderr, then kExitUsage.
int report_no_arguments(CLI::App& app);

}  // namespace neuflow::cli
