#pragma once
// Which checkpoint a subcommand runs: --model, else $NEUFLOW_MODEL, else the published mixed
// weights where `neuflow fetch-model mixed` puts them. The same rule for convert, flow and eval.
#include <string>

namespace neuflow::cli {

inline constexpr const char* kModelEnvironment = "NEUFLOW_MODEL";
inline constexpr const char* kDefaultModel = "models/neuflow_mixed.pth";
inline constexpr const char* kModelOptionHelp =
    "NeuFlow-V2 checkpoint (.pth); default: $NEUFLOW_MODEL, else models/neuflow_mixed.pth (`neuflow fetch-model "
    "mixed` puts it there)";

// `given` (the option's value) when not empty. Otherwise the environment's, or the default file
// when it exists, saying on stderr which it took; CommandError (64) naming all three places when
// there is none.
std::string resolve_model(const std::string& given, const char* subcommand);

}  // namespace neuflow::cli
